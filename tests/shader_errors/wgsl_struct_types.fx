EFFECT.wgsl_struct_types = {
    PASS = {
        a = SHADER.struct_operand { img = IN }
    }
    OUT = a
}
