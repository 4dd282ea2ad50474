// A user's material (docs/materials.md): the pair of stripes.wgsl and
// wrap_lambert.wgsl, both looked up next to this file.
MATERIAL.stripes = {
    DESCRIPTION = "world-space stripes under wrap lighting"
    SURFACE = SHADER.stripes { color_b = (0.6, 0.15, 0.1, 1) width = 0.2 }
    LIGHTING = SHADER.wrap_lambert { wrap = 0.4 }
}
