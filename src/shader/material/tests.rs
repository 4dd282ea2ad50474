//! The material shader checks: the built-in library in every mode, parameters and
//! textures, diagnostics at the user's line and column, and the resource and
//! feature rules.

use super::*;
use crate::graph::library::EMBEDDED_MATERIAL_SHADERS;
use crate::shader::include::tests::MemFs;
use crate::shader::reflect::FieldType;
use crate::shader::rename::prefix_module_names;
use std::path::Path;

const SURFACES: &[&str] = &["standard", "triplanar"];
const LIGHTINGS: &[&str] = &["lambert", "phong", "blinn_phong", "cook_torrance"];

fn load(kind: MaterialShaderKind, name: &str) -> (MaterialShader, SourceMap) {
    let mut sources = SourceMap::new();
    let file = find_material_shader(name, None).expect("built-in");
    match load_material_shader(kind, name, file, &mut sources) {
        Ok(m) => (m, sources),
        Err(ds) => panic!(
            "{}",
            ds.iter().map(|d| d.render(&sources)).collect::<String>()
        ),
    }
}

fn validate(wgsl: &str) {
    let m = naga::front::wgsl::parse_str(wgsl)
        .unwrap_or_else(|e| panic!("{}\n{wgsl}", e.emit_to_string(wgsl)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(&m)
    .unwrap_or_else(|e| panic!("{}\n{wgsl}", e.emit_to_string(wgsl)));
}

/// Load a memory file through `fs` (paths under /m).
fn load_mem(
    kind: MaterialShaderKind,
    fs: &MemFs,
    path: &str,
) -> (Result<MaterialShader, Vec<Diagnostic>>, SourceMap) {
    let mut sources = SourceMap::new();
    let file = ShaderFile {
        shown: path.trim_start_matches("/m/").to_string(),
        text: fs.files[Path::new(path)].clone(),
        path: Some(path.into()),
    };
    let r = load_material_shader_with(kind, "t", file, fs, &mut sources);
    (r, sources)
}

/// The rendered errors of loading a shader of `kind` whose one file is `/m/NAME`.
fn errors_of(kind: MaterialShaderKind, name: &str, src: &str) -> String {
    let path = format!("/m/{name}");
    let fs = MemFs::default().file(&path, src);
    let (r, sources) = load_mem(kind, &fs, &path);
    errors(r, &sources)
}

fn errors(r: Result<MaterialShader, Vec<Diagnostic>>, sources: &SourceMap) -> String {
    match r {
        Ok(_) => panic!("expected errors"),
        Err(ds) => ds.iter().map(|d| d.render(sources)).collect(),
    }
}

#[test]
fn library_lists() {
    let mut names = builtin_material_shaders();
    names.sort();
    assert_eq!(
        names,
        [
            "blinn_phong",
            "cook_torrance",
            "lambert",
            "phong",
            "standard",
            "triplanar"
        ]
    );
    assert!(crate::graph::library::embedded_library_file("lib/brdf.wgsl").is_some());
    assert!(crate::graph::library::embedded_library_file("lib/normal.wgsl").is_some());
    assert!(find_material_shader("lib/brdf", None).is_none());
    assert!(find_material_shader("../shaders/blurX", None).is_none());
    for (name, text) in EMBEDDED_MATERIAL_SHADERS {
        assert!(text.starts_with("//"), "{name} has no header comment");
    }
}

#[test]
fn library_surfaces_in_every_mode() {
    for name in SURFACES {
        let (m, _) = load(MaterialShaderKind::Surface, name);
        assert!(!m.features.is_empty(), "{name}");
        let flags: Vec<&str> = m.flags.iter().map(String::as_str).collect();
        let none: &[&str] = &[];
        for enabled in [flags.as_slice(), none, &flags[..flags.len() / 2]] {
            let t = m
                .wgsl(FeatureMode::Preprocess, enabled, &|f| f.into())
                .unwrap();
            validate(&format!("{t}\n{MATERIAL_INTERFACE}"));
        }
        let t = m.wgsl(FeatureMode::Override, &[], &|f| f.into()).unwrap();
        assert_eq!(
            t.lines().count(),
            m.text.lines().count() + flags.len(),
            "{name}: override mode keeps the lines"
        );
        for f in &flags {
            assert!(t.contains(&format!("override {f}: bool = false;")));
        }
        validate(&format!("{t}\n{MATERIAL_INTERFACE}"));
        let t = m
            .wgsl(FeatureMode::Branch, &[], &|f| {
                let i = flags.iter().position(|x| *x == f).unwrap();
                format!("((fx_features.x & {}u) != 0u)", 1u32 << i)
            })
            .unwrap();
        assert!(t.contains("if ((fx_features.x & "));
        validate(&format!(
            "{t}\n{MATERIAL_INTERFACE}\n{BRANCH_FEATURES_DECL}"
        ));
    }
}

#[test]
fn library_lightings() {
    for name in LIGHTINGS {
        let (m, _) = load(MaterialShaderKind::Lighting, name);
        assert!(m.textures.is_empty() && m.flags.is_empty());
        assert_eq!(
            m.lighting_takes_params,
            matches!(*name, "phong" | "blinn_phong"),
            "{name}"
        );
        for mode in [
            FeatureMode::Preprocess,
            FeatureMode::Override,
            FeatureMode::Branch,
        ] {
            let t = m.wgsl(mode, &[], &|f| f.into()).unwrap();
            validate(&format!("{t}\n{MATERIAL_INTERFACE}"));
        }
    }
    let (phong, _) = load(MaterialShaderKind::Lighting, "phong");
    let p = phong.params.unwrap();
    assert_eq!(p.struct_name, "LightingParams");
    assert_eq!(p.members.len(), 1);
    let m = &p.members[0];
    assert_eq!(
        (m.name.as_str(), m.ty, m.default.clone(), m.range),
        (
            "specular_power",
            FieldType::F32(1),
            Some(vec![32.0]),
            Some((1.0, 4096.0))
        )
    );
    assert!(m.description.contains("SPECULAR_POWER"));
    let (bp, _) = load(MaterialShaderKind::Lighting, "blinn_phong");
    assert_eq!(bp.params.unwrap().members[0].name, "shininess");
}

#[test]
fn renamed_lighting_shaders_share_a_module() {
    let mut module = String::new();
    for (i, name) in LIGHTINGS.iter().enumerate() {
        let (m, _) = load(MaterialShaderKind::Lighting, name);
        let t = m.lighting_wgsl(&format!("lm{i}_")).unwrap();
        assert!(t.contains(&format!("fn lm{i}_lighting(")), "{t}");
        module.push_str(&t);
    }
    // Also by hand, as the brief's minimal case: two shaders with the same names.
    let (a, _) = load(MaterialShaderKind::Lighting, "phong");
    let (b, _) = load(MaterialShaderKind::Lighting, "cook_torrance");
    let (ta, _) = preprocess(&a.text, &[]).unwrap();
    let (tb, _) = preprocess(&b.text, &[]).unwrap();
    let two = format!(
        "{}{}{MATERIAL_INTERFACE}",
        prefix_module_names(&ta, "lm0_", INTERFACE_NAMES).unwrap(),
        prefix_module_names(&tb, "lm1_", INTERFACE_NAMES).unwrap()
    );
    assert!(two.contains("struct lm0_LightingParams"));
    assert!(two.contains("params: lm0_LightingParams"));
    assert!(two.contains("params.specular_power"));
    validate(&two);
    // And they can be called from generated code.
    validate(&format!(
        "{module}{MATERIAL_INTERFACE}\nfn fx_test(i: LightingInput) -> vec3<f32> {{\n    let a = lm0_lighting(i);\n    let b = lm1_lighting(i, lm1_LightingParams(32.0));\n    return a.diffuse + b.specular;\n}}\n"
    ));
}

#[test]
fn standard_params_and_textures() {
    let (m, _) = load(MaterialShaderKind::Surface, "standard");
    let p = m.params.as_ref().unwrap();
    assert_eq!(p.struct_name, "SurfaceParams");
    let get = |n: &str| p.members.iter().find(|x| x.name == n).unwrap();
    assert_eq!(get("base_color").default, Some(vec![1.0; 4]));
    assert_eq!(get("emissive").ty, FieldType::F32(3));
    assert_eq!(get("specular").default, Some(vec![0.04; 3]));
    assert_eq!(get("roughness").range, Some((0.0, 1.0)));
    assert_eq!(get("detail_scale").default, Some(vec![8.0]));
    // vec3s are followed by f32s, so nothing is wasted before the maps.
    assert_eq!(get("metallic").offset, 28);
    assert_eq!(get("roughness").offset, 44);
    assert_eq!(get("base_color_map_uv").offset, 64);
    // + clearcoat, clearcoat_roughness, clearcoat_normal_scale, transmission and
    // the four layer maps' transforms
    assert_eq!(get("clearcoat").offset, 320);
    assert_eq!(get("clearcoat_map_uv").offset, 336);
    assert_eq!(p.size, 464);
    let maps = [
        ("base_color_map", true),
        ("normal_map", false),
        ("metallic_roughness_map", false),
        ("occlusion_map", false),
        ("emissive_map", true),
        ("specular_map", true),
        ("opacity_map", false),
        ("detail_map", true),
        ("clearcoat_map", false),
        ("clearcoat_roughness_map", false),
        ("clearcoat_normal_map", false),
        ("transmission_map", false),
    ];
    assert_eq!(m.textures.len(), maps.len());
    for (t, (name, srgb)) in m.textures.iter().zip(maps) {
        assert_eq!((t.name.as_str(), t.srgb), (name, srgb));
        assert_eq!(
            get(&format!("{name}_uv")).default,
            Some(vec![1.0, 0.0, 0.0, 1.0])
        );
        assert_eq!(
            get(&format!("{name}_uv_offset")).default,
            Some(vec![0.0; 4])
        );
        assert!(m.features.contains(&t.flag), "{} unused", t.flag);
    }
    assert_eq!(m.params_binding, Some(0));
    assert_eq!(m.params_var.as_deref(), Some("material"));
    assert_eq!(m.samplers.len(), 1);
    assert!(m.features.contains(&"HAS_VERTEX_COLOR".to_string()));
    assert!(m.features.contains(&"HAS_TANGENTS".to_string()));
    let (t, _) = load(MaterialShaderKind::Surface, "triplanar");
    let names: Vec<&str> = t
        .params
        .as_ref()
        .unwrap()
        .members
        .iter()
        .map(|m| m.name.as_str())
        .collect();
    assert_eq!(
        names,
        [
            "base_color",
            "specular",
            "metallic",
            "roughness",
            "scale",
            "sharpness",
            "normal_scale"
        ]
    );
    let tex: Vec<(&str, bool)> = t
        .textures
        .iter()
        .map(|t| (t.name.as_str(), t.srgb))
        .collect();
    assert_eq!(tex, [("base_color_map", true), ("normal_map", false)]);
}

const GOOD_SURFACE: &str = "fn surface(in: SurfaceInput) -> SurfaceOutput {\n    var o: SurfaceOutput;\n    o.normal = in.normal;\n    return o;\n}\n";

#[test]
fn type_error_at_users_line_and_column() {
    let src = "#include \"lib/normal.wgsl\"\n\nfn surface(in: SurfaceInput) -> SurfaceOutput {\n    var o: SurfaceOutput;\n#ifdef HAS_VERTEX_COLOR\n    o.diffuse = in.color.rgb;\n#endif\n    let k: f32 = in.normal;\n    return o;\n}\n";
    assert_eq!(
        errors_of(MaterialShaderKind::Surface, "s.wgsl", src),
        "s.wgsl:8:9: error: WGSL: the type of `k` is expected to be `f32`, but got `vec3<f32>`\n  |\n8 |     let k: f32 = in.normal;\n  |         ^ definition of `k`\n  = note: with the feature flags `HAS_VERTEX_COLOR` defined\n"
    );
    // A validation error (not caught by the front end).
    let src = "fn surface(in: SurfaceInput) -> SurfaceOutput {\n    var o: SurfaceOutput;\n    o.diffuse = in.normal + in.uv0.xy;\n    return o;\n}\n";
    let text = errors_of(MaterialShaderKind::Surface, "s.wgsl", src);
    assert!(text.starts_with("s.wgsl:3:17: error: WGSL"), "{text}");
    assert!(
        !text.contains("Vector {") && !text.contains("Scalar {"),
        "{text}"
    );
}

#[test]
fn error_inside_included_file() {
    let fs = MemFs::default()
        .file(
            "/m/s.wgsl",
            &format!("#include \"inc/helpers.wgsl\"\n{GOOD_SURFACE}"),
        )
        .file(
            "/m/inc/helpers.wgsl",
            "// helpers\nfn twice(x: f32) -> f32 {\n    return x * undefined_name;\n}\n",
        );
    let (r, sources) = load_mem(MaterialShaderKind::Surface, &fs, "/m/s.wgsl");
    let text = errors(r, &sources);
    assert!(
        text.starts_with("/m/inc/helpers.wgsl:3:16: error: WGSL: no definition in scope for identifier: `undefined_name`\n  |\n3 |     return x * undefined_name;\n  |                ^^^^^^^^^^^^^^"),
        "{text}"
    );
    // A missing include: at the directive.
    assert!(errors_of(
        MaterialShaderKind::Surface,
        "s.wgsl",
        &format!("{GOOD_SURFACE}  #include \"gone.wgsl\"\n")
    )
    .starts_with("s.wgsl:6:3: error: cannot find included file `gone.wgsl`"));
}

#[test]
fn wrong_signature() {
    let src = "fn surface(in: SurfaceInput) -> vec4<f32> {\n    return vec4<f32>(1.0);\n}\n";
    assert_eq!(
        errors_of(MaterialShaderKind::Surface, "s.wgsl", src),
        "s.wgsl:1:1: error: `surface` must be `fn surface(in: SurfaceInput) -> SurfaceOutput`; found `fn surface(in: SurfaceInput) -> vec4<f32>`\n  |\n1 | fn surface(in: SurfaceInput) -> vec4<f32> {\n  | ^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^ wrong signature\n"
    );
    assert!(errors_of(MaterialShaderKind::Surface, "s.wgsl", "fn surfac(in: SurfaceInput) -> SurfaceOutput {\n    var o: SurfaceOutput;\n    return o;\n}\n")
        .starts_with("s.wgsl:1:1: error: the surface shader defines no `surface` function"));
    assert!(errors_of(MaterialShaderKind::Lighting, "l.wgsl", "fn lighting(in: LightingInput, k: f32) -> LightingOutput {\n    return LightingOutput(in.light * k, vec3<f32>(0.0));\n}\n")
        .contains("found `fn lighting(in: LightingInput, k: f32) -> LightingOutput`"));
}

#[test]
fn interface_clash_and_entry_points() {
    let src = format!("struct SurfaceInput {{ a: f32 }}\n{GOOD_SURFACE}");
    let text = errors_of(MaterialShaderKind::Surface, "s.wgsl", &src);
    assert!(
        text.starts_with("s.wgsl:1:8: error: WGSL: redefinition of `SurfaceInput`"),
        "{text}"
    );
    let src = format!("@fragment\n{GOOD_SURFACE}");
    let text = errors_of(MaterialShaderKind::Surface, "s.wgsl", &src);
    assert!(
        text.starts_with(
            "s.wgsl:1:1: error: a material shader has no entry points: remove `@fragment`"
        ),
        "{text}"
    );
}

#[test]
fn lighting_with_texture_rejected() {
    let src = "@group(2) @binding(0) var t: texture_2d<f32>;\nfn lighting(in: LightingInput) -> LightingOutput {\n    return LightingOutput(in.light, vec3<f32>(0.0));\n}\n";
    let text = errors_of(MaterialShaderKind::Lighting, "l.wgsl", src);
    assert!(
        text.starts_with(
            "l.wgsl:1:23: error: a lighting shader declares no resources: `t` is one\n"
        ),
        "{text}"
    );
}

#[test]
fn surface_resource_rules() {
    let src = format!(
        "struct SurfaceParams {{\n    k: f32, // @default(1, 2)\n}}\n@group(2) @binding(0) var<uniform> p: SurfaceParams;\n@group(2) @binding(16) var a: texture_2d<f32>;\n@group(1) @binding(1) var b: texture_2d<f32>;\n@group(2) @binding(2) var c: texture_2d<f32>; // @gamma\n@group(2) @binding(3) var<storage> d: array<f32>;\n@group(2) @binding(0) var s: sampler;\nfn fx_helper() {{}}\n{GOOD_SURFACE}"
    );
    let text = errors_of(MaterialShaderKind::Surface, "s.wgsl", &src);
    assert!(
        text.contains("s.wgsl:10:4: error: `fx_helper`: names starting with `fx_`"),
        "{text}"
    );
    let src = src.replace("fn fx_helper() {}\n", "");
    let text = errors_of(MaterialShaderKind::Surface, "s.wgsl", &src);
    for want in [
        "s.wgsl:5:24: error: `a` is at @group(2) @binding(16)",
        "s.wgsl:6:23: error: `b` is at @group(1) @binding(1)",
        "s.wgsl:7:50: error: unknown texture annotation `@gamma`",
        "s.wgsl:8:23: error: unsupported resource `d` of type `array<f32>`",
        "s.wgsl:9:23: error: @binding(0) is used twice",
        "s.wgsl:2:5: error: `@default` of `k` has 2 values, the field has 1",
    ] {
        assert!(text.contains(want), "missing {want:?} in\n{text}");
    }
}

#[test]
fn feature_rules() {
    // A typo in a texture flag.
    let src = "@group(2) @binding(0) var base_map: texture_2d<f32>;\n@group(2) @binding(1) var smp: sampler;\nfn surface(in: SurfaceInput) -> SurfaceOutput {\n    var o: SurfaceOutput;\n#ifdef HAS_BASEMAP\n    o.diffuse = textureSample(base_map, smp, in.uv0).rgb;\n#endif\n    return o;\n}\n";
    let text = errors_of(MaterialShaderKind::Surface, "s.wgsl", src);
    assert!(
        text.starts_with("s.wgsl:5:1: error: `HAS_BASEMAP` is not a feature flag of this shader"),
        "{text}"
    );
    assert!(text.contains("did you mean `HAS_BASE_MAP`?"), "{text}");
    // Fixed, it loads; the flag is known.
    let fs = MemFs::default().file("/m/s.wgsl", &src.replace("HAS_BASEMAP", "HAS_BASE_MAP"));
    let (r, _) = load_mem(MaterialShaderKind::Surface, &fs, "/m/s.wgsl");
    let m = r.unwrap();
    assert_eq!(m.features, ["HAS_BASE_MAP"]);
    assert_eq!(m.flags.last().map(String::as_str), Some("HAS_BASE_MAP"));
    // A block that declares something used after it: fine when preprocessed,
    // wrong as an `if` statement.
    let src = "fn surface(in: SurfaceInput) -> SurfaceOutput {\n    var o: SurfaceOutput;\n#ifdef HAS_UV1\n    let uv = in.uv1;\n#else\n    let uv = in.uv0;\n#endif\n    o.roughness = uv.x;\n    return o;\n}\n";
    let text = errors_of(MaterialShaderKind::Surface, "s.wgsl", src);
    assert!(
        text.starts_with("s.wgsl:8:19: error: WGSL: no definition in scope for identifier: `uv`"),
        "{text}"
    );
    assert!(text.contains("note: in override mode"), "{text}");
    // A flag around a declaration.
    let src = "#ifdef HAS_UV1\nconst K = 1.0;\n#endif\nfn surface(in: SurfaceInput) -> SurfaceOutput {\n    var o: SurfaceOutput;\n    return o;\n}\n";
    assert!(errors_of(MaterialShaderKind::Surface, "s.wgsl", src)
        .starts_with("s.wgsl:1:1: error: feature flag `HAS_UV1` used outside a function"));
}

#[test]
fn sanitized_types() {
    assert_eq!(
        sanitize("Operation Add can't work with [2] (of type Vector { size: Tri, scalar: Scalar { kind: Float, width: 4 } }) and [4] (of type Matrix { columns: Bi, rows: Bi, scalar: Scalar { kind: Float, width: 4 } })"),
        "operator `+` can't work with `vec3<f32>` and `mat2x2<f32>`"
    );
    assert_eq!(
        sanitize("Function [0] 'f' is invalid"),
        "function `f` is invalid"
    );
    assert_eq!(sanitize("x[3] ok"), "x[3] ok");
}
