// Materials of the built-in benchmark scene `builtin:bench`: a floor and eight
// sphere colours, the paper's Phong model with increasing specular powers.

MATERIAL.floor = {
    SURFACE = SHADER.standard { base_color = (0.5, 0.5, 0.5, 1) specular = (0.2, 0.2, 0.2) }
    LIGHTING = SHADER.phong { SPECULAR_POWER = 16 }
}
MATERIAL.bench_0 = { SURFACE = SHADER.standard { base_color = (0.9, 0.3, 0.43, 1) specular = (0.2, 0.2, 0.2) } LIGHTING = SHADER.phong { SPECULAR_POWER = 8 } }
MATERIAL.bench_1 = { SURFACE = SHADER.standard { base_color = (0.8, 0.19, 0.68, 1) specular = (0.3, 0.3, 0.3) } LIGHTING = SHADER.phong { SPECULAR_POWER = 16 } }
MATERIAL.bench_2 = { SURFACE = SHADER.standard { base_color = (0.55, 0.2, 0.9, 1) specular = (0.4, 0.4, 0.4) } LIGHTING = SHADER.phong { SPECULAR_POWER = 32 } }
MATERIAL.bench_3 = { SURFACE = SHADER.standard { base_color = (0.3, 0.35, 0.85, 1) specular = (0.5, 0.5, 0.5) } LIGHTING = SHADER.phong { SPECULAR_POWER = 64 } }
MATERIAL.bench_4 = { SURFACE = SHADER.standard { base_color = (0.2, 0.6, 0.8, 1) specular = (0.6, 0.6, 0.6) } LIGHTING = SHADER.phong { SPECULAR_POWER = 128 } }
MATERIAL.bench_5 = { SURFACE = SHADER.standard { base_color = (0.3, 0.85, 0.5, 1) specular = (0.7, 0.7, 0.7) } LIGHTING = SHADER.phong { SPECULAR_POWER = 256 } }
MATERIAL.bench_6 = { SURFACE = SHADER.standard { base_color = (0.55, 0.9, 0.25, 1) specular = (0.8, 0.8, 0.8) } LIGHTING = SHADER.phong { SPECULAR_POWER = 512 } }
MATERIAL.bench_7 = { SURFACE = SHADER.standard { base_color = (0.85, 0.65, 0.2, 1) specular = (0.9, 0.9, 0.9) } LIGHTING = SHADER.phong { SPECULAR_POWER = 1024 } }
