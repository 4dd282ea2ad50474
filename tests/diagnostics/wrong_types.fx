EFFECT.e = {
    DESCRIPTION = 42
    PARAM = {
        n = INT { DEFAULT = 1.5 }
        v = VEC3 { DEFAULT = (1, 2) }
        b = BOOL { DEFAULT = 1 }
        m = ENUM { VALUES = (fast, fine)  DEFAULT = slow }
    }
    PASS = {
        a = SHADER.s {
            img = IN
            OUT.SIZE = "big"
            OUT.SCALE = (1, 2, 3)
            gain = "loud"
            img.WRAP = sideways
            DEFINE.MODE = 2.5
        }
    }
    OUT = a
}
