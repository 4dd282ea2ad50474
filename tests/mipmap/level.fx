// One level of the chain of an input of any size (tests/mipmap.rs), in the
// output's top-left corner.
EFFECT.level = {
    PARAM = {
        level = INT { DEFAULT = 1  RANGE = (0, 8)  DESCRIPTION = "the mip level shown" }
    }
    PASS = {
        show = SHADER.mip_level {
            img = IN
            img.MIPMAP = true
            DEFINE.LEVEL = PARAM.level
            OUT.FORMAT = rgba8
        }
    }
    OUT = show
}
