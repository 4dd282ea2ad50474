EFFECT.missing_shader = {
    PASS = {
        a = SHADER.does_not_exist { img = IN }
    }
    OUT = a
}
