EFFECT.wgsl_types = {
    PASS = {
        a = SHADER.type_error { img = IN }
    }
    OUT = a
}
