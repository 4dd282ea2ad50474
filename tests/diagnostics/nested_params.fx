EFFECT.inner = {
    PARAM = {
        sigma = FLOAT { DEFAULT = 2  RANGE = (0.1, 64)  DESCRIPTION = "blur radius" }
        on = BOOL { DEFAULT = true }
    }
    PASS = { x = SHADER.s { img = IN  sigma = PARAM.sigma } }
    OUT = x
}
EFFECT.outer = {
    PARAM = {
        level = INT { DEFAULT = 3 }
    }
    PASS = {
        a = EFFECT.inner { IN = IN  sigma = 100 }
        b = EFFECT.inner { IN = PASS.a  sigm = 3 }
        c = EFFECT.inner { IN = PASS.b  on = PARAM.level  img = IN }
        d = EFFECT.inner { sigma = 1 }
        e = SHADER.s { img = PASS.d  DEFINE.MODE = PARAM.level  word = fast }
    }
    OUT = e
}
