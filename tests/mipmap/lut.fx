// An auxiliary image of its own size (tests/mipmap.rs).
EFFECT.lut = {
    PASS = {
        show = SHADER.lut_show {
            lut = AUX.lut
            lut.FILTER = nearest
            OUT.FORMAT = rgba8
        }
    }
    OUT = show
}
