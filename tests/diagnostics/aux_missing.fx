// Checked without a scene: only the inputs the command line provides exist.
EFFECT.e = {
    PASS = {
        a = SHADER.s { img = IN  bg = AUX.background }
    }
    OUT = a
}
