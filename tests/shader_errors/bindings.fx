// Every binding mistake at once: an input the shader lacks, a texture the
// script does not bind (in the second pass), an unknown parameter, a value of
// the wrong type, one out of the @range, and a parameter without default unset.
EFFECT.bindings = {
    PASS = {
        a = SHADER.probe {
            image = IN
            gain = 9
            offst = (1, 2, 3)
        }
        b = SHADER.probe {
            img = PASS.a
            gain = (1, 2)
            offset = (0, 0, 0)
        }
    }
    OUT = b
}
