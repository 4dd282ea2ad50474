// motion_blur: per-pixel motion blur along the motion vectors, with foreground and
// background kept apart by depth, after McGuire, Hennessy, Bukowski and Osman, "A
// reconstruction filter for plausible motion blur" (I3D 2012).
//
// Inputs: IN, the sharp frame (linear light); AUX.motion, the motion vectors in
// pixels (current minus previous position, x right, y down: a point at p was at
// p - motion one frame earlier); AUX.depth, linear depth (larger is farther).
//
// Model: the shutter is open for `shutter` of the frame interval, centred on the
// frame time, and objects move linearly: a point at p is seen along the segment
// p +- motion * shutter / 2. Its half-vector h = motion * shutter / 2 is shortened
// to radius = min(max_length / 2, narrowest tile): the blur is at most max_length
// pixels long.
//
// Passes:
// 1. tile_h, tile_v (shaders/effects/motion_blur/motion_blur_tilemax.wgsl): the longest motion vector of each
//    tile of about 32 x 32 pixels (OUT.SCALE 1/32 on each axis in turn; a pixel x
//    belongs to tile floor(x tiles / width)).
// 2. neighbor (shaders/effects/motion_blur/motion_blur_neighbor.wgsl): the longest vector of each tile's 3x3
//    tiles: every pixel whose blur can reach the tile is in one of them.
// 3. blur (shaders/effects/motion_blur/motion_blur_gather.wgsl), per pixel X with neighbour-max half-vector hn:
//    if |hn| <= 0.5 px, X is returned as it is (static regions cost one lookup).
//    Otherwise `samples` pixels Y = X + hn t, t evenly spaced in (-1, 1) with a
//    per-pixel offset (interleaved gradient noise), are weighted by
//      a(Y) = front(Y) cone(|X - Y|, |h(Y)|)      Y in front, blurred over X
//           + back(Y)  cone(|X - Y|, |h(X)|)      Y behind X, seen through X's blur
//           + 2 cylinder(|X - Y|, |h(Y)|) cylinder(|X - Y|, |h(X)|)   both blurred
//    with cone(d, l) = clamp(1 - d / l, 0, 1), cylinder(d, l) = 1 - smoothstep(0.95 l,
//    1.05 l, d), |h| at least 0.5 px, front(Y) = clamp(1 - (z(Y) - z(X)) / e, 0, 1),
//    back(Y) = clamp(1 - (z(X) - z(Y)) / e, 0, 1) and e = soft_depth * z(X) (a soft
//    depth test, relative to the depth). X itself weighs 1 / |h(X)|; the result is
//    the weighted mean of rgba (alpha blurred like colour: premultiplied).
//    So a static pixel receives only the blur of moving things that pass over it
//    in front of it, a moving object's interior only its own colours, and a static
//    object behind a moving one stays sharp where the mover's blur does not reach.
//
// Parameters:
//   shutter     fraction of the frame interval the shutter is open (default 0.5:
//               a 180-degree shutter)
//   samples     samples per blurred pixel (default 15)
//   max_length  longest blur in pixels (default 64, which is also the limit: the
//               tiles are 32 px)
//   soft_depth  depth difference, relative to the pixel's depth, over which a
//               sample goes from in front to behind (default 0.05)
//
// Cost: the tile passes read the motion image once; the blur pass reads one
// texel where nothing moves nearby, otherwise 3 + 3 x samples texels.
// Temporal behaviour: none (one frame, its motion vectors).
EFFECT.motion_blur = {
    DESCRIPTION = "Motion blur along AUX.motion (McGuire et al. 2012): tile and neighbour max velocity, depth-aware reconstruction filter.\nshutter: fraction of the frame interval; static things in front stay sharp."
    PARAM = {
        shutter = FLOAT { DEFAULT = 0.5  RANGE = (0, 1)  DESCRIPTION = "fraction of the frame interval the shutter is open, centred on the frame time" }
        samples = INT { DEFAULT = 15  RANGE = (3, 63)  DESCRIPTION = "samples along the blur per blurred pixel" }
        max_length = FLOAT { DEFAULT = 64  RANGE = (0, 64)  DESCRIPTION = "longest blur in pixels (the 32-pixel tiles limit it to 64)" }
        soft_depth = FLOAT { DEFAULT = 0.05  RANGE = (0.0001, 10)  DESCRIPTION = "depth difference, relative to the pixel's depth, over which a sample goes from in front to behind" }
    }
    PASS = {
        tile_h = SHADER.motion_blur_tilemax {
            motion = AUX.motion
            DEFINE.AXIS = 0
            OUT.SCALE = (0.03125, 1)
            OUT.FORMAT = rg32f
        }
        tile_v = SHADER.motion_blur_tilemax {
            motion = PASS.tile_h
            DEFINE.AXIS = 1
            OUT.SCALE = (1, 0.03125)
            OUT.RELATIVE_TO = motion
            OUT.FORMAT = rg32f
        }
        neighbor = SHADER.motion_blur_neighbor {
            tiles = PASS.tile_v
            OUT.SCALE = 1
            OUT.RELATIVE_TO = tiles
            OUT.FORMAT = rg32f
        }
        blur = SHADER.motion_blur_gather {
            img = IN
            motion = AUX.motion
            depth = AUX.depth
            neighbor = PASS.neighbor
            shutter = PARAM.shutter
            samples = PARAM.samples
            max_length = PARAM.max_length
            soft_depth = PARAM.soft_depth
        }
    }
    OUT = blur
}
