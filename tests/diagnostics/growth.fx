// Checked for a 1920x1080 input: a 6x pass is a warning, a 10x one an error.
EFFECT.e = {
    PASS = {
        grow = SHADER.s { img = IN  OUT.SCALE = 6 }
        toobig = SHADER.s { img = PASS.grow  OUT.SCALE = 10 }
        self = SHADER.s {
            img = PASS.self[-1]
            OUT.SCALE = 0.5
            OUT.RELATIVE_TO = img
        }
        final = SHADER.s { a = PASS.toobig  b = PASS.self }
    }
    OUT = final
}
