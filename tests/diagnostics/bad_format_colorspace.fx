EFFECT.e = {
    FORMAT = rgba9
    PASS = {
        a = SHADER.s {
            img = IN
            OUT.FORMAT = rgb16f
            OUT.COLORSPACE = aces
        }
    }
    OUT = a
}
