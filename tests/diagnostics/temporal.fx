EFFECT.t = {
    PASS = {
        a = SHADER.s { img = IN  future = PASS.a[+1] }
        b = SHADER.s { img = PASS.a  d = AUX.depth[-1] }
        c = SHADER.s { img = PASS.b  far = IN[-40] }
    }
    OUT = c
}
