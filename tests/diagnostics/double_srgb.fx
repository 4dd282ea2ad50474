EFFECT.e = {
    PASS = {
        a = SHADER.s { img = IN  OUT.FORMAT = rgba8-srgb  OUT.COLORSPACE = srgb }
    }
    OUT = a
}
