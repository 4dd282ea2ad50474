EFFECT.loop = {
    PASS = {
        a = SHADER.s { img = IN  other = PASS.c }
        b = SHADER.s { img = PASS.a }
        c = SHADER.s { img = PASS.b }
        d = SHADER.s { img = PASS.c }
    }
    OUT = d
}
