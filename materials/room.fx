// Materials of the built-in scene `builtin:room` (see docs/materials.md).
// Each names a surface shader and a lighting shader from shaders/materials/.

MATERIAL.floor = {
    DESCRIPTION = "checker tiles projected from world space (the box has no tiling UVs)"
    SURFACE = SHADER.triplanar {
        base_color_map = "builtin:checker"
        base_color = (0.75, 0.72, 0.68, 1)
        scale = 2
        sharpness = 8
        roughness = 0.6
    }
    LIGHTING = SHADER.cook_torrance
}

MATERIAL.wall = {
    SURFACE = SHADER.standard { base_color = (0.7, 0.7, 0.72, 1) roughness = 0.9 }
    LIGHTING = SHADER.lambert
}

MATERIAL.red = {
    DESCRIPTION = "the paper's Phong model"
    SURFACE = SHADER.standard { base_color = (0.8, 0.1, 0.08, 1) specular = (0.3, 0.3, 0.3) }
    LIGHTING = SHADER.phong { SPECULAR_POWER = 64 }
}

MATERIAL.blue = {
    SURFACE = SHADER.standard { base_color = (0.1, 0.2, 0.8, 1) specular = (0.5, 0.5, 0.5) }
    LIGHTING = SHADER.blinn_phong { shininess = 128 }
}

MATERIAL.gold = {
    DESCRIPTION = "a metal: glTF metallic-roughness under Cook-Torrance"
    SURFACE = SHADER.standard { base_color = (1, 0.77, 0.34, 1) metallic = 1 roughness = 0.45 }
    LIGHTING = SHADER.cook_torrance
}

MATERIAL.white = {
    SURFACE = SHADER.standard { base_color = (0.85, 0.85, 0.85, 1) roughness = 0.25 }
    LIGHTING = SHADER.cook_torrance
}

MATERIAL.green = {
    DESCRIPTION = "a brick texture on the box's UVs"
    SURFACE = SHADER.standard { base_color_map = "builtin:bricks" base_color = (0.6, 1, 0.6, 1) roughness = 0.8 }
    LIGHTING = SHADER.phong { SPECULAR_POWER = 16 }
}

MATERIAL.lamp = {
    SURFACE = SHADER.standard { base_color = (1, 0.6, 0.2, 1) emissive = (4, 2, 0.6) }
    LIGHTING = SHADER.lambert
}

MATERIAL.glass = {
    SURFACE = SHADER.standard { base_color = (0.6, 0.85, 1, 0.35) roughness = 0.05 }
    LIGHTING = SHADER.cook_torrance
    ALPHA = blend
}
