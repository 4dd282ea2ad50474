EFFECT.e = {
    PASS = {
        zero = SHADER.s { img = IN  OUT.SIZE = (0, 10) }
        huge = SHADER.s { img = IN  OUT.SIZE = (20000, 10) }
        negative = SHADER.s { img = IN  OUT.SCALE = (-1, 1) }
        fraction = SHADER.s { img = IN  OUT.SIZE = (10.5, 3) }
        final = SHADER.s { b = PASS.zero  c = PASS.huge  d = PASS.negative  e = PASS.fraction }
    }
    OUT = final
}
