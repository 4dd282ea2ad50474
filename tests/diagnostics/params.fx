EFFECT.outer = {
    PARAM = {
        strength = FLOAT { DEFAULT = 200  RANGE = (0, 10) }
        gain = FLOAT { DEFAULT = 1  RANGE = (5, 1) }
        mode = ENUM { DEFAULT = 1 }
        extra = FLOAT { DEFAULT = 1  UNIT = px }
    }
    PASS = {
        c = SHADER.s { img = IN  k = PARAM.gian }
    }
    OUT = c
}
