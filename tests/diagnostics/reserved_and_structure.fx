GLOBAL = 3
EFFECT.e = {
    PASS = {
        IN = SHADER.s { img = IN }
        a.b = SHADER.s { img = IN }
        c = 5
        d = SHADER.s { IN = IN }
        e = EFFECT.inner { img = IN }
    }
    OUT = PASS.c.d
}
EFFECT.inner = { OUT = IN }
