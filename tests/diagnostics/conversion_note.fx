EFFECT.e = {
    PASS = {
        encoded = SHADER.s { img = IN  OUT.COLORSPACE = srgb }
        reads_linear = SHADER.s { img = PASS.encoded }
    }
    OUT = reads_linear
}
