EFFECT.e = {
    PARAM = {
        k = FLOAT { DEFAULT = 1 }
        k = FLOAT { DEFAULT = 2 }
    }
    PASS = {
        a = SHADER.s { img = IN  OUT.SCALE = 0.5  OUT.SCALE = 0.25 }
        a = SHADER.t { img = IN }
    }
    OUT = a
}
EFFECT.e = { OUT = IN }
