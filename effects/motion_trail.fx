// motion_trail: moving bright things leave a fading trail (feedback decay).
//
// Maths (shaders/effects/motion_trail/motion_trail.wgsl), per pixel, with prev = this pass's own output of the
// previous frame (feedback PASS.trail[-1]; zero before the first frame):
//   mode = max  out = max(cur, decay * prev)           (per channel, alpha too)
//               A pixel that a bright object left k frames ago holds
//               decay^k times its value (until the current image is brighter
//               there); the image itself is never darkened nor brightened. The
//               trail of a static object is the object: nothing changes.
//   mode = add  out = cur + decay * prev               (alpha: min(., 1))
//               An infinite-impulse-response echo: out(t) = sum_k decay^k cur(t - k).
//               Left-behind pixels on black also decay as decay^k, but static
//               content brightens towards cur / (1 - decay) (5x at decay 0.8):
//               meant for bright objects on dark backgrounds (sparks, HUDs).
//   decay = 0 gives the input unchanged in both modes.
//
// Parameters:
//   decay  fraction of the trail kept per frame (0 .. 1, default 0.8)
//   mode   max (default) or add
//
// Passes: one, `trail` (SHADER.motion_trail: cur = IN, prev = PASS.trail[-1]) at the input's
// size in rgba16f (HDR sums do not clip and the decay is not quantised to 8 bits).
// Temporal behaviour: feedback only; no latency, no input history.
EFFECT.motion_trail = {
    DESCRIPTION = "Motion trail: out = max(cur, decay * previous out), or cur + decay * previous out (mode = add)."
    PARAM = {
        decay = FLOAT { DEFAULT = 0.8  RANGE = (0, 1)  DESCRIPTION = "fraction of the trail kept from one frame to the next" }
        mode = ENUM { VALUES = (max, add)  DEFAULT = max  DESCRIPTION = "max: the brighter of the frame and the fading trail; add: the frame plus the fading trail" }
    }
    PASS = {
        trail = SHADER.motion_trail {
            cur = IN
            prev = PASS.trail[-1]
            decay = PARAM.decay
            DEFINE.MODE = PARAM.mode
        }
    }
    OUT = trail
}
