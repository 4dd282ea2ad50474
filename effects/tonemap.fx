// tonemap: HDR to display range.
//
// In linear light, x = max(in, 0) * 2^exposure, then the operator:
//   reinhard:  per channel y = x / (1 + x);  with white > 0 (Reinhard extended):
//              y = x (1 + x / white^2) / (1 + x), so that x = white maps to 1
//   aces:      per channel, Krzysztof Narkowicz's fit of the ACES filmic curve (2015):
//              y = x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14)
//              (no built-in 0.6 pre-exposure: set exposure = -0.737 for it)
//   neutral:   Khronos PBR Neutral, per its published specification (the glTF
//              Sample Viewer's default): offset = (m < 0.08 ? m - 6.25 m^2 : 0.04)
//              with m the smallest channel, c = x - offset; colours whose largest
//              channel p stays below 0.8 - 0.04 are unchanged (base colours
//              reproduce); above, p' = 1 - d^2 / (p + d - 0.76) with d = 0.24,
//              c *= p' / p, then mixed towards (p', p', p') by
//              g = 1 - 1 / (0.15 (p - p') + 1) (desaturation 0.15)
//   agx:       AgX (Troy Sobotka; Blender's default view transform): the inset
//              matrix, log2 over [-12.47393, 4.026069] EV mapped to [0, 1], the
//              base contrast sigmoid as the 6th-order polynomial fit of Benjamin
//              Wrensch's "minimal AgX" (no LUT), the look (base, or punchy: power
//              1.35 and saturation 1.4), the outset matrix, then a 2.2 power back
//              to linear display light
//   bt2390:    ITU-R BT.2390 EETF (section 5.4, black level 0), the default for
//              PQ and HLG video: in the PQ domain on the largest BT.2020 component
//              (libplacebo's "max" mode), from the source peak to target_peak with
//              the knee ks = (1 + knee) maxLum - knee (knee 0.5 is BT.2390's) and
//              the black level lift to the display's black (target_peak /
//              contrast; 1000:1 by default, as libplacebo assumes for SDR); the
//              colour is scaled by the ratio; y = the BT.1886 signal of that
//              display (black Lb) raised to 2.4, so that a 2.4-gamma (BT.1886)
//              encoding writes the signal, as libplacebo's output does.
//              The source peak is source_peak (set by fxrun from the video's
//              MaxCLL, else its mastering display peak), or, when 0, measured on
//              the frame: passes p1 (1/8 size) -> p2 (1 x 1)
//              reduce the PQ code of every
//              pixel's largest BT.2020 component to its (peak, average). This
//              effect keeps no state (images, batches, the viewer); for PQ and HLG
//              video fxrun runs effects/tonemap_video.fx instead, the same effect
//              with the measured peak smoothed over frames and reset at scene cuts
//   gamut:     desaturate (default): out-of-gamut colours (a negative BT.709
//              channel, e.g. from BT.2020 video) are moved towards their luminance
//              before the curve, and BT.2390's results above 1 towards white
//              after it, instead of clipping each channel; clip: channels clipped
//   out = clamp(y, 0, 1)
// The result is display-referred linear light in [0, 1], ready for an 8-bit file
// (the runtime applies the sRGB encoding when writing it) or an SDR video (fxrun
// writes it as BT.709 / BT.1886 and tags it so: docs/cli.md, "HDR video").
// Scale: HDR input values are linear BT.709 with 1.0 = 203 cd/m² (what fxrun
// decodes PQ and HLG video to).
//
// Parameters:
//   exposure  stops applied before the curve (-20 .. 20, default 0)
//   operator  reinhard | aces | neutral | agx (default aces)
//   white     Reinhard extended white point, in scene values after exposure
//             (0 = plain Reinhard, the default; ignored by the others)
//   look      AgX look: base | punchy (default base; ignored by the others)
//   source_peak  bt2390: source peak in cd/m² (0 = measured per frame, default)
//   target_peak  bt2390: display peak in cd/m², output 1.0 (default 203: SDR)
//   knee      bt2390: knee offset, 0.5 (BT.2390, default) to 2
//   source_black  bt2390: source black in cd/m² (default 0.005)
//   contrast  bt2390: display contrast, black = target_peak / contrast (default
//             1000; 0: black 0)
//   smoothing, scene_low, scene_high  used by tonemap_video only (the same
//             parameters, so that a --set works for both)
//   gamut     desaturate | clip (default desaturate)
//
// Passes: p1 (1/8 size), p2 (1 x 1) (under compute execution compute
// passes with a tree in workgroup memory), tonemap (SHADER.tonemap,
// input size).
EFFECT.tonemap = {
    DESCRIPTION = "Tone mapping of HDR images and video to [0, 1]: exposure, then Reinhard (extended), ACES (Narkowicz fit), Khronos PBR Neutral, AgX (base or punchy) or the ITU-R BT.2390 EETF (source peak from metadata or measured on the frame); out-of-gamut colours desaturated."
    PARAM = {
        exposure = FLOAT { DEFAULT = 0  RANGE = (-20, 20)  DESCRIPTION = "exposure in stops applied before the curve" }
        operator = ENUM { VALUES = (reinhard, aces, neutral, agx, bt2390)  DEFAULT = aces  DESCRIPTION = "tone curve: reinhard (x / (1 + x), extended with white), aces (Narkowicz fit), neutral (Khronos PBR Neutral), agx (AgX, Blender's) or bt2390 (ITU-R BT.2390 EETF, fxrun's default for PQ and HLG video)" }
        white = FLOAT { DEFAULT = 0  RANGE = (0, 65000)  DESCRIPTION = "Reinhard extended: the value mapped to 1; 0 = plain Reinhard" }
        look = ENUM { VALUES = (base, punchy)  DEFAULT = base  DESCRIPTION = "AgX look: base contrast, or punchy (power 1.35, saturation 1.4)" }
        source_peak = FLOAT { DEFAULT = 0  RANGE = (0, 10000)  DESCRIPTION = "bt2390: the source's peak in cd/m² (0: measured per frame)" }
        target_peak = FLOAT { DEFAULT = 203  RANGE = (80, 10000)  DESCRIPTION = "bt2390: the display's peak in cd/m² (output 1.0)" }
        knee = FLOAT { DEFAULT = 0.5  RANGE = (0.5, 2)  DESCRIPTION = "bt2390: knee offset (0.5 is BT.2390's, 1 libplacebo's default)" }
        source_black = FLOAT { DEFAULT = 0.005  RANGE = (0, 100)  DESCRIPTION = "bt2390: the source's black in cd/m² (0.005: a typical HDR black, libplacebo's)" }
        contrast = FLOAT { DEFAULT = 1000  RANGE = (0, 1000000)  DESCRIPTION = "bt2390: the display's contrast: black = target_peak / contrast (1000: SDR, libplacebo's; 0: black 0)" }
        smoothing = FLOAT { DEFAULT = 20  RANGE = (1, 1000)  DESCRIPTION = "bt2390, tonemap_video (fxrun's choice for HDR video) only: frames the measured peak is averaged over" }
        scene_low = FLOAT { DEFAULT = 1  RANGE = (0, 100)  DESCRIPTION = "bt2390, tonemap_video only: average-brightness change (% PQ) where a scene cut starts to count" }
        scene_high = FLOAT { DEFAULT = 3  RANGE = (0, 100)  DESCRIPTION = "bt2390, tonemap_video only: average-brightness change (% PQ) that restarts the peak measurement" }
        gamut = ENUM { VALUES = (clip, desaturate)  DEFAULT = desaturate  DESCRIPTION = "out-of-gamut colours: desaturated towards white (keeps hue) or clipped per channel" }
    }
    PASS = {
        p1 = SHADER.tonemap_peak {
            img = IN
            exposure = PARAM.exposure
            DEFINE.FIRST = 1
            OUT.SCALE = 0.125
            OUT.FORMAT = rgba32f
        }
        p2 = SHADER.tonemap_peak { img = PASS.p1  OUT.SIZE = (1, 1)  OUT.FORMAT = rgba32f }
        tonemap = SHADER.tonemap {
            img = IN
            state = PASS.p2
            exposure = PARAM.exposure
            white = PARAM.white
            source_peak = PARAM.source_peak
            target_peak = PARAM.target_peak
            knee = PARAM.knee
            source_black = PARAM.source_black
            contrast = PARAM.contrast
            smoothing = PARAM.smoothing
            scene_low = PARAM.scene_low
            scene_high = PARAM.scene_high
            DEFINE.OPERATOR = PARAM.operator
            DEFINE.LOOK = PARAM.look
            DEFINE.GAMUT = PARAM.gamut
        }
    }
    OUT = tonemap
}
