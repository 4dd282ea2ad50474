EFFECT.wgsl_syntax = {
    PASS = {
        a = SHADER.broken { img = IN }
    }
    OUT = a
}
