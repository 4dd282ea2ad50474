EFFECT.e = {
    PASS = {
        a = SHADER.s { img = IN }
    }
}
