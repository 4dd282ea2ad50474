// dof: depth of field from the deferred renderer's linear depth.
//
// What it does
//   Blurs what is in front of and behind the focal band by its circle of confusion
//   (CoC), keeping the band sharp, with separate far and near fields so that a sharp
//   object neither leaks a halo onto the blurred background nor gets the background
//   smeared over it, while a blurred foreground does spread over what is behind it.
//
// Inputs: IN (the scene), AUX.depth (linear view-space depth).
//
// Maths
//   CoC (shaders/effects/dof/dof_coc.wgsl), signed radius in pixels, thin-lens shape with a
//   sharp band of depth `focal_range` around `focus_distance`:
//       s_near = max(focus_distance - focal_range / 2, 0), s_far = focus_distance + focal_range / 2
//       d > s_far:  c =  aperture * (1 - s_far / d)     far field, -> aperture at infinity
//       d < s_near: c = -aperture * (s_near / d - 1)    near field (negative)
//       else        c = 0                               in focus
//       c = clamp(c, -max_radius, max_radius); no geometry (depth 0): c = aperture.
//   (The thin-lens CoC A f |d - s| / (d (s - f)) is proportional to |1 - s / d| when
//   the focal length f << s.)
//   Far field (shaders/effects/dof/dof_far.wgsl): gather over the disc of radius c_p with
//   `samples` golden-angle taps (texel loads); near-field taps are skipped; a tap's
//   CoC is limited to the centre's, e_q = min(c_q, c_p), it covers p by
//   clamp(e_q - |q - p| + 0.5, 0, 1) and weighs coverage / e_q^2. A sharp pixel
//   (|c_p| < 0.5) is returned exactly; a sharp foreground tap (e_q = 0) never
//   reaches a background pixel: no halo, no background bleeding onto the sharp
//   object. A near-field pixel gets the mean of the non-near taps of its disc: the
//   background seen through the near field's semi-transparent edge.
//   Near field (shaders/effects/dof/dof_nearmax.wgsl, dof_near.wgsl): R = the largest near CoC
//   within max_radius (separable max filter); gather over the disc of radius R of
//   near taps only, weight coverage / a_q^2 (a_q = -c_q); the near colour is their
//   weighted mean and its coverage alpha = the collected weight divided by that of
//   a uniform near field of CoC R (1 inside a blurred foreground more than its CoC
//   from the silhouette, about 1/2 at the silhouette, 0 at its CoC outside it).
//       out = mix(far(p), near colour, alpha)     (all four channels)
//
// Parameters:
//   focus_distance  view-space distance in focus (default 10)
//   focal_range     depth of the sharp band around it (default 2)
//   aperture        CoC radius in pixels of an object at infinity (default 8)
//   max_radius      largest CoC radius in pixels, near field included (default 16)
//   samples         gather taps per field, 8..128 (default 48; a shader define)
//
// Limitations: gather, not scatter: at most `samples` taps per disc, so very large
// CoCs get grainy (taps are texel loads, unfiltered); CoC radii are capped at
// max_radius; the background behind a blurred near object is estimated from the
// visible non-near pixels around it (no hidden-layer data).
//
// Passes (input size):
//   coc        SHADER.dof_coc      AUX.depth -> signed CoC (r16f)
//   far        SHADER.dof_far      IN, coc -> far field + in-focus (rgba16f)
//   nearmax_h  SHADER.dof_nearmax  coc -> horizontal max of the near CoC (r16f)
//   nearmax_v  SHADER.dof_nearmax  nearmax_h -> vertical max (r16f)
//   final      SHADER.dof_near     IN, coc, far, nearmax_v -> near field composited
//                                  over the far field (IN's format)
EFFECT.dof = {
    DESCRIPTION = "Depth of field from AUX.depth: thin-lens CoC, far and near gather fields without halos.\nSharp band of focal_range around focus_distance; aperture = CoC radius (px) at infinity."
    PARAM = {
        focus_distance = FLOAT { DEFAULT = 10  RANGE = (0.0001, 1000000)  DESCRIPTION = "view-space distance in focus" }
        focal_range = FLOAT { DEFAULT = 2  RANGE = (0, 1000000)  DESCRIPTION = "depth of the sharp band around the focus distance" }
        aperture = FLOAT { DEFAULT = 8  RANGE = (0, 64)  DESCRIPTION = "CoC radius in pixels of an object at infinity" }
        max_radius = FLOAT { DEFAULT = 16  RANGE = (0, 64)  DESCRIPTION = "largest CoC radius in pixels (limits the near field)" }
        samples = INT { DEFAULT = 48  RANGE = (8, 128)  DESCRIPTION = "gather taps per pixel and field" }
    }
    PASS = {
        coc = SHADER.dof_coc {
            depth = AUX.depth
            focus_distance = PARAM.focus_distance
            focal_range = PARAM.focal_range
            aperture = PARAM.aperture
            max_radius = PARAM.max_radius
            OUT.FORMAT = r16f
        }
        far = SHADER.dof_far {
            img = IN
            coc = PASS.coc
            DEFINE.SAMPLES = PARAM.samples
            OUT.FORMAT = rgba16f
        }
        nearmax_h = SHADER.dof_nearmax {
            src = PASS.coc
            max_radius = PARAM.max_radius
            OUT.FORMAT = r16f
        }
        nearmax_v = SHADER.dof_nearmax {
            src = PASS.nearmax_h
            max_radius = PARAM.max_radius
            DEFINE.VERTICAL = 1
            OUT.FORMAT = r16f
        }
        final = SHADER.dof_near {
            img = IN
            coc = PASS.coc
            far = PASS.far
            nearmax = PASS.nearmax_v
            DEFINE.SAMPLES = PARAM.samples
            OUT.FORMAT = IN
        }
    }
    OUT = final
}
