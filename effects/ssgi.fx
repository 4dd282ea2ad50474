// ssgi: screen-space global illumination: one bounce of indirect diffuse light
// from the deferred renderer's G-buffer and lit scene.
//
// What it does
//   Adds to every surface the light that the other visible surfaces reflect onto
//   it: a red wall tints the white floor beside it, a lit floor brightens the
//   underside of objects. It adds only this bounce; it never darkens (occlusion is
//   ssao's job, see "With ssao and the environment" below).
//
// Inputs: IN (the lit scene: its pixels are the radiance the senders reflect),
// AUX.depth, AUX.normal (view space), AUX.albedo (the receiver's diffuse colour),
// AUX.motion (temporal reprojection), and the camera's proj / inv_proj standard
// values. The renderer (fxrun --scene) publishes all of them.
//
// Method (after Ritschel, Grosch and Seidel 2009, "Approximating dynamic global
// illumination in image space": screen-space directional occlusion with an
// indirect bounce, where each hemisphere sample that hits a visible surface
// brings that pixel's light). Ritschel treats each sample point as a small patch
// of an assumed area; here each sample is instead a short ray marched in view
// space to its first hit, so that the estimate converges to the irradiance
// integral itself (the form factors of the senders) and not to a patch
// approximation of it:
//   E(P) = integral over the hemisphere of L(w) cos(theta) dw,
//   added radiance = intensity * albedo(P) * E / pi
// 1. trace (shaders/effects/ssgi/ssgi_trace.wgsl): `directions` cosine-distributed directions
//    per pixel, each pixel of a 4x4 block taking every 16th direction of one
//    evenly spread set of 16 x `directions` (a Fibonacci spiral; the set turns
//    each frame), each marched in `steps` samples out to `radius`; a
//    sample hits the surface of the pixel it projects to when it lies behind
//    that surface's depth by at most `thickness`, and a step that went through
//    a surface (from in front of it to far behind it or past its silhouette) hits
//    it where it crosses the surface's plane. The hit's IN colour is
//    L(w) (the radiance it sends to the camera, taken as what it sends to P: a
//    diffuse sender); a hit on the back of a surface (its normal facing away
//    from P) ends the ray in the dark: light does not pass through walls. No hit
//    within the radius, or leaving the image: no bounce from that direction.
//    With cosine-distributed directions, E / pi = the mean of the L(w).
// 2. accum (shaders/effects/ssgi/ssgi_accum.wgsl): temporal accumulation along AUX.motion: the
//    running mean of up to `frames` frames, dropped on a disocclusion (depth
//    change beyond `depth_tolerance`, relative) or outside the frame, the history
//    clamped to mean +- clip_gamma sigma of the 3x3 current estimates.
// 3. final (shaders/effects/ssgi/ssgi_out.wgsl): a 5x5 depth- and normal-aware blur of the
//    accumulated E / pi (the weights of ssao's blur, `blur_tolerance`), times the
//    receiver's albedo and `intensity`, added to IN (output = indirect: the added
//    light alone).
//
// With ssao and the environment (no occlusion counted twice)
//   ssgi adds light and never multiplies IN. The renderer's environment term is
//   occluded only by the material's occlusion; `ssao` multiplies the scene by its
//   AO. Run `ssao ssgi` (ssgi after ssao): the occlusion is then applied once (by
//   ssao, to the direct and environment light), and the bounce once (by ssgi),
//   not darkened again: each ray already stops at the first surface, which is the
//   bounce's own occlusion. The senders' light read from IN is then ssao's
//   output, as it is on screen. `ssgi ssao` would darken the bounce by the AO a
//   second time. The bounce carries everything IN holds: the punctual lights, the
//   environment and emission of the senders (one bounce of all of them).
//
// Parameters:
//   radius          longest ray in view-space units (default 2; scene scale)
//   directions      rays per pixel, 1..32 (default 8; a shader define)
//   steps           samples per ray, 2..64 (default 12; a shader define)
//   thickness       assumed thickness of a surface behind its depth (default 0.5)
//   bias            ray start offset along the normal and tangent-plane test (0.02)
//   intensity       scales the bounce (default 1: physically based)
//   frames          most frames the temporal history stands for (default 8; 1: off)
//   depth_tolerance relative depth change that drops the history (default 0.1)
//   clip_gamma      history clamping box half-width in standard deviations (2)
//   blur_tolerance  blur: plane distance, relative to depth, where a tap's weight
//                   falls to 1/e (default 0.02)
//   blur            false: skip the spatial blur
//   output          composite (IN + bounce) or indirect (the bounce alone)
//
// Limitations: screen-space: only what is on screen sends light (an off-screen or
// hidden sender gives nothing; the bounce fades at the image border); senders are
// taken as diffuse (a mirror's IN colour is sent in every direction); the depth
// buffer has no back faces, so a ray passing behind a thin object within
// `thickness` counts as blocked; thin objects between two samples of a ray can be
// missed; a small, very bright sender (a lamp) that few of a pixel's rays meet
// gives speckles on a single frame (the temporal filter averages them over
// frames). Cost: directions x steps depth reads per pixel (docs/renderer.md).
//
// Passes:
//   trace   SHADER.ssgi_trace  IN, AUX.depth, AUX.normal -> E / pi (rgb), depth (a); rgba16f
//   accum   SHADER.ssgi_accum  trace, trace[-1], accum[-1], AUX.motion -> mean (rgb), n (a); rgba16f
//   final   SHADER.ssgi_out    IN, accum, AUX.depth, AUX.normal, AUX.albedo -> IN + bounce (IN's format)
EFFECT.ssgi = {
    DESCRIPTION = "Screen-space global illumination: one bounce of diffuse light from IN (rays through AUX.depth), denoised in time (AUX.motion) and space.\nAdds light only: run it after ssao (ssao ssgi). Needs the renderer's G-buffer (depth, normal, albedo, motion)."
    PARAM = {
        radius = FLOAT { DEFAULT = 2  RANGE = (0.0001, 100000)  DESCRIPTION = "longest ray in view-space units" }
        directions = INT { DEFAULT = 8  RANGE = (1, 32)  DESCRIPTION = "rays per pixel (cosine-distributed)" }
        steps = INT { DEFAULT = 12  RANGE = (2, 64)  DESCRIPTION = "samples per ray, denser near the pixel" }
        thickness = FLOAT { DEFAULT = 0.5  RANGE = (0.0001, 100000)  DESCRIPTION = "assumed thickness of a surface behind its depth, view-space units" }
        bias = FLOAT { DEFAULT = 0.02  RANGE = (0, 100000)  DESCRIPTION = "ray start offset along the normal and tangent-plane bias, view-space units" }
        intensity = FLOAT { DEFAULT = 1  RANGE = (0, 100)  DESCRIPTION = "scales the bounce (1: physically based)" }
        frames = FLOAT { DEFAULT = 8  RANGE = (1, 64)  DESCRIPTION = "most frames the temporal history stands for (1: no temporal filter)" }
        depth_tolerance = FLOAT { DEFAULT = 0.1  RANGE = (0, 10)  DESCRIPTION = "relative depth change beyond which the reprojected history is dropped" }
        clip_gamma = FLOAT { DEFAULT = 2  RANGE = (0.25, 100)  DESCRIPTION = "history clamping box half-width, in standard deviations of the 3x3 current estimates" }
        blur_tolerance = FLOAT { DEFAULT = 0.02  RANGE = (0.00001, 10)  DESCRIPTION = "blur: distance from the pixel's tangent plane, relative to its depth, where a tap's weight falls to 1/e" }
        blur = BOOL { DEFAULT = true  DESCRIPTION = "5x5 depth- and normal-aware blur of the bounce" }
        output = ENUM { VALUES = (composite, indirect)  DEFAULT = composite  DESCRIPTION = "composite: IN plus the bounce; indirect: the added bounce alone" }
    }
    PASS = {
        trace = SHADER.ssgi_trace {
            img = IN
            depth = AUX.depth
            normal = AUX.normal
            radius = PARAM.radius
            thickness = PARAM.thickness
            bias = PARAM.bias
            DEFINE.DIRECTIONS = PARAM.directions
            DEFINE.STEPS = PARAM.steps
            OUT.FORMAT = rgba16f
        }
        accum = SHADER.ssgi_accum {
            cur = PASS.trace
            cur_prev = PASS.trace[-1]
            hist = PASS.accum[-1]
            motion = AUX.motion
            frames = PARAM.frames
            depth_tolerance = PARAM.depth_tolerance
            clip_gamma = PARAM.clip_gamma
            OUT.FORMAT = rgba16f
        }
        final = SHADER.ssgi_out {
            img = IN
            gi = PASS.accum
            depth = AUX.depth
            normal = AUX.normal
            albedo = AUX.albedo
            intensity = PARAM.intensity
            depth_tolerance = PARAM.blur_tolerance
            DEFINE.BLUR = PARAM.blur
            DEFINE.OUTPUT = PARAM.output
            OUT.FORMAT = IN
        }
    }
    OUT = final
}
