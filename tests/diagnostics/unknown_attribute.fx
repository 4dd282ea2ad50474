EFFECT.e = {
    SPEED = 3
    PASS = {
        a = SHADER.s {
            img = IN
            OUT.SCAL = (0.5, 0.5)
            img.FILTR = nearest
            BLEND.MODE = add
        }
    }
    OUT = a
}
