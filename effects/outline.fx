// outline: outlines from depth and normal discontinuities of the G-buffer, drawn
// over the scene, as a mask, or used for edge anti-aliasing.
//
// Inputs: IN (the scene), AUX.depth (linear view-space depth), AUX.normal
// (view-space normal), inv_proj (identity without a renderer).
//
// Detection (shaders/effects/outline/outline_detect.wgsl), for every pair of 4-neighbours p, q with
// view-space positions P, Q (from depth with inv_proj) and unit normals n_p, n_q:
//   depth edge:   max(|dot(Q - P, n_p)|, |dot(Q - P, n_q)|) > depth_threshold * min(d_p, d_q)
//                 the distance of each pixel from the other's tangent plane, relative
//                 to depth: exactly 0 across a plane however slanted or grazing (a
//                 plain depth difference would flag grazing floors), large across a
//                 step; with a zero normal, |d_q - d_p| is used.
//   normal edge:  dot(n_p, n_q) < cos(normal_threshold)   (a crease, depth continuous)
//   silhouette:   exactly one of p, q has geometry (depth > 0 and finite).
// The outline pixel of an edge is its nearer side (d_p <= d_q; no geometry counts as
// infinitely far; both at equal depth): a line one pixel wide on the silhouette of
// the nearer surface, none on smooth or flat regions.
//
// Drawing (shaders/effects/outline/outline_apply.wgsl):
//   coverage c(p) = max over outline pixels q of clamp(width - |q - p|, 0, 1)
//   overlay:    out = vec4(mix(IN.rgb, color, opacity * c), IN.a)
//   mask:       out = vec4(c, c, c, 1)     (white outline on black)
//   antialias:  out = mix(IN(p), mean of IN(q) over the neighbours q across an edge
//               of p, strength / 2): both pixels of every edge pair are blended
//               towards each other (strength 1: to their average); other pixels
//               are unchanged.
//
// Limitations: normals must be consistently oriented (towards the camera), else a
// flipped normal reads as a crease; the antialias mode blends whole pixels across
// an edge (no sub-pixel edge position search, unlike fxaa).
//
// Parameters: mode, depth_threshold, normal_threshold, color, opacity, width,
// strength (below).
// Passes:
//   detect  SHADER.outline_detect  AUX.depth, AUX.normal -> outline mask and edge
//                                  bits (rgba16f)
//   apply   SHADER.outline_apply   IN, detect -> output (IN's format)
EFFECT.outline = {
    DESCRIPTION = "Outlines from depth and normal discontinuities (AUX.depth, AUX.normal): overlay, mask or edge anti-aliasing.\nDepth edges are measured off the neighbour's tangent plane, so slanted surfaces give none."
    PARAM = {
        mode = ENUM { VALUES = (overlay, mask, antialias)  DEFAULT = overlay  DESCRIPTION = "overlay: draw the outline over IN; mask: the outline alone; antialias: blend across the edges" }
        depth_threshold = FLOAT { DEFAULT = 0.1  RANGE = (0, 1000000)  DESCRIPTION = "distance off the neighbour's tangent plane, relative to depth, that makes an edge" }
        normal_threshold = FLOAT { DEFAULT = 30  RANGE = (0, 180)  DESCRIPTION = "angle between neighbouring normals (degrees) that makes an edge" }
        color = VEC3 { DEFAULT = (0, 0, 0)  RANGE = (0, 65504)  DESCRIPTION = "outline colour (linear)" }
        opacity = FLOAT { DEFAULT = 1  RANGE = (0, 1)  DESCRIPTION = "outline opacity" }
        width = FLOAT { DEFAULT = 1  RANGE = (1, 8)  DESCRIPTION = "outline width in pixels (fractional widths are soft)" }
        strength = FLOAT { DEFAULT = 1  RANGE = (0, 1)  DESCRIPTION = "antialias mode: blend across edges (1: edge pairs become their average)" }
    }
    PASS = {
        detect = SHADER.outline_detect {
            depth = AUX.depth
            normal = AUX.normal
            depth_threshold = PARAM.depth_threshold
            normal_threshold = PARAM.normal_threshold
            OUT.FORMAT = rgba16f
        }
        apply = SHADER.outline_apply {
            img = IN
            edges = PASS.detect
            color = PARAM.color
            opacity = PARAM.opacity
            width = PARAM.width
            strength = PARAM.strength
            DEFINE.MODE = PARAM.mode
            OUT.FORMAT = IN
        }
    }
    OUT = apply
}
