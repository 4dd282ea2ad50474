EFFECT.again = {
    PASS = {
        a = EFFECT.again { IN = IN }
    }
    OUT = a
}
