//! Generates the renderer's WGSL from templates (`shaders/render/`) and the
//! materials' surface and lighting shaders (the materials-and-effects paper: "the vertex and pixel shader
//! code is generated from the high-level shaders by a template that supports
//! several light sources").
//!
//! A geometry module = the engine part + the shadow lookups + the geometry
//! template and its layers (clear coat, transmission) + one surface shader + one lighting shader (renamed `lmK_*`, K its
//! model id) + the interface types. The light module = the engine part + the
//! shadow lookups + the light template +
//! every lighting shader of the scene + a dispatch on the model id stored in the
//! G-buffer. Feature flags are then resolved per [`VariantMode`].

use super::{MaterialSet, ShaderInfo, VariantKey, VariantMode};
use crate::shader::features::{convert_features, to_override_mode};
use crate::shader::material::{INTERFACE_NAMES, MATERIAL_INTERFACE};
use crate::shader::preprocess::preprocess;
use std::fmt::Write as _;

const ENGINE: &str = concat!(
    include_str!("../../../shaders/render/engine.wgsl"),
    include_str!("../../../shaders/render/instance.wgsl"),
    include_str!("../../../shaders/render/environment.wgsl")
);
const GEOMETRY: &str = concat!(
    include_str!("../../../shaders/render/geometry.wgsl"),
    include_str!("../../../shaders/render/layers.wgsl")
);
const LIGHT: &str = include_str!("../../../shaders/render/light.wgsl");
/// Shadow-map lookups: both modules shade through `fx_light_sample_shadowed`.
const SHADOW: &str = include_str!("../../../shaders/render/shadow.wgsl");

/// Binding of the per-material feature bits in group 2 (run-time-branching mode).
pub const FEATURES_BINDING: u32 = 16;

/// A generated module and what its pipelines must set.
#[derive(Debug, Clone)]
pub struct Generated {
    pub wgsl: String,
    /// Pipeline-overridable constants (override mode): name → value.
    pub constants: Vec<(String, f64)>,
}

/// Name prefix of lighting model `k`'s declarations.
pub fn model_prefix(k: usize) -> String {
    format!("lm{k}_")
}

fn renamed_lighting(k: usize, l: &ShaderInfo) -> Result<String, String> {
    let _ = INTERFACE_NAMES;
    l.shader
        .lighting_wgsl(&model_prefix(k))
        .map_err(|e| format!("lighting shader `{}`: {e}", l.name))
}

/// `@group(3) @binding(K) var<storage, read> fx_lpK: array<lmK_LightingParams>;`
fn params_decl(k: usize, l: &ShaderInfo) -> String {
    if l.takes_params() {
        format!(
            "@group(3) @binding({k}) var<storage, read> fx_lp{k}: array<{}LightingParams>;\n",
            model_prefix(k)
        )
    } else {
        String::new()
    }
}

fn call(k: usize, l: &ShaderInfo) -> String {
    if l.takes_params() {
        format!("{}lighting(li, fx_lp{k}[material])", model_prefix(k))
    } else {
        format!("{}lighting(li)", model_prefix(k))
    }
}

/// The environment term of lighting shader `k`: its `environment` (renamed
/// `lmK_environment`) when it has one, else the engine's default term.
fn environment_call(k: usize, l: &ShaderInfo) -> String {
    match l.shader.environment {
        Some(true) => format!(
            "{}environment(fx_env_with_bright(e), fx_lp{k}[material])",
            model_prefix(k)
        ),
        Some(false) => format!("{}environment(fx_env_with_bright(e))", model_prefix(k)),
        None => "fx_environment_default(e)".to_string(),
    }
}

/// `fx_environment_lighting` of a geometry module: its lighting shader's term.
fn environment_dispatch(k: usize, l: &ShaderInfo) -> String {
    format!(
        "fn fx_environment_lighting(material: u32, e: EnvironmentInput) -> LightingOutput {{\n    return {};\n}}\n",
        environment_call(k, l)
    )
}

/// `fx_environment_lighting` of the light module (the deferred composition
/// adds the environment there): a switch on the material's lighting model.
fn environment_model_dispatch(set: &MaterialSet) -> String {
    let mut text = String::from(
        "fn fx_environment_lighting(material: u32, e: EnvironmentInput) -> LightingOutput {\n    switch fx_materials[material].model {\n",
    );
    // only the models with an environment function of their own: the others
    // share the default term's one copy (a switch case each would inline it
    // once per model, and lanes of different models would run it twice)
    for (k, l) in set.lightings.iter().enumerate() {
        if l.shader.environment.is_some() {
            writeln!(
                text,
                "        case {k}u: {{ return {}; }}",
                environment_call(k, l)
            )
            .unwrap();
        }
    }
    text.push_str("        default: { return fx_environment_default(e); }\n    }\n}\n");
    text
}

fn header(normal_encoding: u32) -> String {
    format!("const NORMAL_ENCODING: u32 = {normal_encoding}u;\n")
}

/// The geometry module of variant `key` (forward loop bound `light_count` in the
/// preprocessor mode; ignored otherwise).
pub fn geometry_module(
    set: &MaterialSet,
    key: VariantKey,
    mode: VariantMode,
    light_count: u32,
    normal_encoding: u32,
) -> Result<Generated, String> {
    let s = &set.surfaces[key.surface];
    let l = &set.lightings[key.lighting];
    let k = key.lighting;
    let mut text = header(normal_encoding);
    text.push_str(ENGINE);
    text.push('\n');
    text.push_str(SHADOW);
    text.push('\n');
    text.push_str(GEOMETRY);
    text.push('\n');
    text.push_str(&s.shader.text);
    text.push('\n');
    text.push_str(&renamed_lighting(k, l)?);
    text.push('\n');
    text.push_str(&params_decl(k, l));
    writeln!(
        text,
        "fn fx_lighting(material: u32, li: LightingInput) -> LightingOutput {{\n    return {};\n}}",
        call(k, l)
    )
    .unwrap();
    text.push_str(&environment_dispatch(k, l));
    text.push_str(MATERIAL_INTERFACE);
    resolve(text, &s.flags, key.features, mode, light_count)
}

/// The light module (light volumes, composition, G-buffer resolve) for every
/// lighting model of the scene.
pub fn light_module(set: &MaterialSet, normal_encoding: u32) -> Result<Generated, String> {
    let mut text = header(normal_encoding);
    text.push_str(ENGINE);
    text.push('\n');
    text.push_str(SHADOW);
    text.push('\n');
    text.push_str(LIGHT);
    // light.wgsl's compute AUX resolve encodes albedo with it.
    text.push_str(crate::shader::compute::SRGB_ENCODE);
    text.push('\n');
    let mut dispatch = String::from(
        "fn fx_lighting_model(model: u32, material: u32, li: LightingInput) -> LightingOutput {\n    switch model {\n",
    );
    for (k, l) in set.lightings.iter().enumerate() {
        text.push_str(&renamed_lighting(k, l)?);
        text.push('\n');
        text.push_str(&params_decl(k, l));
        writeln!(dispatch, "        case {k}u: {{ return {}; }}", call(k, l)).unwrap();
    }
    dispatch.push_str(
        "        default: { return LightingOutput(vec3<f32>(0.0), vec3<f32>(0.0)); }\n    }\n}\n",
    );
    text.push_str(&dispatch);
    text.push_str(&environment_model_dispatch(set));
    text.push_str(MATERIAL_INTERFACE);
    let (wgsl, _) = preprocess(&text, &[]).map_err(|e| e.message)?;
    Ok(Generated {
        wgsl,
        constants: Vec::new(),
    })
}

/// Resolves the feature flags of `text` for `mode`.
fn resolve(
    text: String,
    flags: &[String],
    features: u64,
    mode: VariantMode,
    light_count: u32,
) -> Result<Generated, String> {
    let on = |i: usize| features & (1 << i) != 0;
    let flag_refs: Vec<&str> = flags.iter().map(String::as_str).collect();
    match mode {
        VariantMode::Preprocess => {
            let mut defines: Vec<(String, i64)> = flags
                .iter()
                .enumerate()
                .filter(|(i, _)| on(*i))
                .map(|(_, f)| (f.clone(), 1))
                .collect();
            defines.push(("FX_LIGHT_COUNT".into(), i64::from(light_count.max(1))));
            let (wgsl, _) = preprocess(&text, &defines).map_err(|e| e.message)?;
            // `const FX_LIGHT_COUNT = N;` is appended by the preprocessor.
            Ok(Generated {
                wgsl,
                constants: Vec::new(),
            })
        }
        VariantMode::Override => {
            let converted = to_override_mode(&text, &flag_refs).map_err(|e| e.message)?;
            let (mut wgsl, _) = preprocess(&converted, &[]).map_err(|e| e.message)?;
            let constants: Vec<(String, f64)> = flags
                .iter()
                .enumerate()
                .map(|(i, f)| (f.clone(), if on(i) { 1.0 } else { 0.0 }))
                .collect();
            wgsl.push_str("override FX_LIGHT_COUNT: u32 = 1u;\n");
            let mut constants = constants;
            constants.push(("FX_LIGHT_COUNT".into(), f64::from(light_count.max(1))));
            Ok(Generated { wgsl, constants })
        }
        VariantMode::Branch => {
            let converted = convert_features(&text, &flag_refs, |f| {
                let bit = flags.iter().position(|x| x == f).unwrap_or(63);
                format!(
                    "((fx_features[{}] & {}u) != 0u)",
                    bit / 32,
                    1u64 << (bit % 32)
                )
            })
            .map_err(|e| e.message)?;
            let (mut wgsl, _) = preprocess(&converted, &[]).map_err(|e| e.message)?;
            wgsl = wgsl.replace("FX_LIGHT_COUNT", "fx_frame.light_count");
            writeln!(
                wgsl,
                "@group(2) @binding({FEATURES_BINDING}) var<uniform> fx_features: vec4<u32>;"
            )
            .unwrap();
            Ok(Generated {
                wgsl,
                constants: Vec::new(),
            })
        }
    }
}

/// The feature bits of the run-time-branching uniform for `features`.
pub fn feature_words(features: u64) -> [u32; 4] {
    [features as u32, (features >> 32) as u32, 0, 0]
}
