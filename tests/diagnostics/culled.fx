EFFECT.e = {
    PASS = {
        used = SHADER.s { img = IN }
        forgotten = SHADER.s { img = PASS.used }
    }
    OUT = used
}
