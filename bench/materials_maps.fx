// The standard surface in nine map combinations, for bench/materials.sh: every
// material of builtin:bench (floor, bench_0..7) replaced by name. Textures are
// the built-in procedural ones, so the benchmark needs no files.

MATERIAL.bench_0 = {
    DESCRIPTION = "no maps"
    SURFACE = SHADER.standard { base_color = (0.9, 0.3, 0.43, 1) roughness = 0.4 }
    LIGHTING = SHADER.cook_torrance
}
MATERIAL.bench_1 = {
    DESCRIPTION = "base colour"
    SURFACE = SHADER.standard { base_color_map = "builtin:checker" roughness = 0.4 }
    LIGHTING = SHADER.cook_torrance
}
MATERIAL.bench_2 = {
    DESCRIPTION = "base colour, normal"
    SURFACE = SHADER.standard { base_color_map = "builtin:checker" normal_map = "builtin:bumps" }
    LIGHTING = SHADER.cook_torrance
}
MATERIAL.bench_3 = {
    DESCRIPTION = "base colour, normal, metallic-roughness"
    SURFACE = SHADER.standard { base_color_map = "builtin:bricks" normal_map = "builtin:bumps" metallic_roughness_map = "builtin:checker" }
    LIGHTING = SHADER.cook_torrance
}
MATERIAL.bench_4 = {
    DESCRIPTION = "base colour, normal, metallic-roughness, occlusion"
    SURFACE = SHADER.standard { base_color_map = "builtin:bricks" normal_map = "builtin:bumps" metallic_roughness_map = "builtin:checker" occlusion_map = "builtin:checker" }
    LIGHTING = SHADER.cook_torrance
}
MATERIAL.bench_5 = {
    DESCRIPTION = "five maps: + emissive"
    SURFACE = SHADER.standard { base_color_map = "builtin:checker" normal_map = "builtin:bumps" metallic_roughness_map = "builtin:checker" occlusion_map = "builtin:checker" emissive_map = "builtin:bricks" emissive = (0.2, 0.2, 0.2) }
    LIGHTING = SHADER.cook_torrance
}
MATERIAL.bench_6 = {
    DESCRIPTION = "seven maps: + specular, opacity"
    SURFACE = SHADER.standard { base_color_map = "builtin:checker" normal_map = "builtin:bumps" metallic_roughness_map = "builtin:checker" occlusion_map = "builtin:checker" emissive_map = "builtin:bricks" specular_map = "builtin:checker" opacity_map = "builtin:checker" }
    LIGHTING = SHADER.cook_torrance
}
MATERIAL.bench_7 = {
    DESCRIPTION = "all eight maps"
    SURFACE = SHADER.standard { base_color_map = "builtin:checker" normal_map = "builtin:bumps" metallic_roughness_map = "builtin:checker" occlusion_map = "builtin:checker" emissive_map = "builtin:bricks" specular_map = "builtin:checker" opacity_map = "builtin:checker" detail_map = "builtin:bricks" }
    LIGHTING = SHADER.cook_torrance
}
MATERIAL.floor = {
    DESCRIPTION = "all eight maps"
    SURFACE = SHADER.standard { base_color_map = "builtin:bricks" normal_map = "builtin:bumps" metallic_roughness_map = "builtin:checker" occlusion_map = "builtin:checker" emissive_map = "builtin:bricks" specular_map = "builtin:checker" opacity_map = "builtin:checker" detail_map = "builtin:checker" }
    LIGHTING = SHADER.cook_torrance
}
