EFFECT.e = {
    PASS = {
        a = EFFECT.gaussian_blurr { IN = IN }
    }
    OUT = a
}
