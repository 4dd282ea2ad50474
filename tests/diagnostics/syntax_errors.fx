// Two broken effects: both syntax errors are reported, and the good effect
// between them is still checked.
EFFECT.a = {
    PASS = {
        p = SHADER.s { img IN }
    }
    OUT = p
}
EFFECT.ok = {
    PASS = { p = SHADER.s { img = PASS.nope } }
    OUT = p
}
EFFECT.b = {
    PASS = { p = SHADER.s { img = IN  t = (1, 2 } }
    OUT = p
}
