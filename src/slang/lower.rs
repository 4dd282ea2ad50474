//! A preset lowered to an effect on disk: the EFFECT script and one WGSL file per
//! pass, written to a content-addressed folder of the temporary directory, so the
//! lookup serves it as any `.fx` file (and its shaders are found beside it).

use super::compile::{compile_pass, load_source, parameters, preset_semantics, Source};
use super::error::SlangError;
use super::rewrite::{plan_fields, rewrite_fragment, rewrite_vertex};
use super::script::{needs_source, script, PassPlan, ScriptInput};
use super::vertex::combine;
use super::words::replace_word;
use crate::unwind::catch_quiet;
use librashader_preprocess::ShaderParameter;
use librashader_presets::{ShaderFeatures, ShaderPreset};
use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};
use std::sync::{LazyLock, Mutex};

/// A lowered preset.
#[derive(Debug, Clone)]
pub struct Lowered {
    /// The generated effect file (`EFFECT.NAME`, named like the preset).
    pub fx: PathBuf,
    /// The preset's LUT textures: `AUX.NAME` inputs and their image files.
    pub luts: Vec<(String, PathBuf)>,
}

/// True when `arg` names a slang preset (`*.slangp`).
pub fn is_preset(arg: &str) -> bool {
    Path::new(arg)
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("slangp"))
}

/// Parses the preset at `path` (its `#reference` chain and wildcards resolved).
pub fn parse_preset(path: &Path) -> Result<ShaderPreset, SlangError> {
    let parsed = catch_quiet(|| ShaderPreset::try_parse(path, ShaderFeatures::NONE));
    let preset = parsed
        .map_err(|panic| preset_error(path, format!("the preset parser failed: {panic}")))?
        .map_err(|e| preset_error(path, e.to_string()))?;
    if preset.passes.is_empty() {
        return Err(preset_error(path, "the preset has no passes".into()));
    }
    Ok(preset)
}

fn preset_error(path: &Path, message: String) -> SlangError {
    SlangError::Preset {
        path: path.to_path_buf(),
        message,
    }
}

/// The files a preset is read from, for `--watch`: the preset itself, each
/// pass's shader and each LUT image (files the shaders `#include` are not
/// known before preprocessing, and are not listed).
pub fn preset_files(path: &Path) -> Result<Vec<PathBuf>, SlangError> {
    let preset = parse_preset(path)?;
    let mut files = vec![path.to_path_buf()];
    files.extend(preset.passes.iter().map(|p| p.path.clone()));
    files.extend(preset.textures.iter().map(|t| t.path.clone()));
    Ok(files)
}

/// Lowers the preset at `path` and writes the effect (or finds it written). A
/// preset is lowered once per process for one content (the command line and the
/// lookup both ask): the memo is keyed by the parsed preset (its `#reference`s
/// resolved) and each pass's preprocessed text (its includes in it), so an
/// edited preset or shader (`--watch`) is lowered again.
pub fn lower_preset(path: &Path) -> Result<Lowered, SlangError> {
    static DONE: LazyLock<Mutex<HashMap<u64, Lowered>>> = LazyLock::new(Mutex::default);
    let preset = parse_preset(path)?;
    let sources = preset
        .passes
        .iter()
        .map(|p| load_source(&p.path))
        .collect::<Result<Vec<Source>, SlangError>>()?;
    let key = content_key(path, &preset, &sources);
    let done = || DONE.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(l) = done().get(&key) {
        return Ok(l.clone());
    }
    let lowered = lower_uncached(path, preset, &sources)?;
    done().insert(key, lowered.clone());
    Ok(lowered)
}

/// What a lowering depends on: the preset's path, its parsed settings and each
/// pass's preprocessed stages.
fn content_key(path: &Path, preset: &ShaderPreset, sources: &[Source]) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    path.hash(&mut h);
    format!("{preset:?}").hash(&mut h);
    for s in sources {
        s.path.hash(&mut h);
        s.source.vertex.hash(&mut h);
        s.source.fragment.hash(&mut h);
    }
    h.finish()
}

fn lower_uncached(
    path: &Path,
    preset: ShaderPreset,
    sources: &[Source],
) -> Result<Lowered, SlangError> {
    let params = with_preset_values(parameters(sources), &preset);
    let effect = effect_name(path);
    let mut shaders = Vec::new();
    let mut plans = Vec::new();
    let last = preset.passes.len() - 1;
    let semantics = preset_semantics(&preset, sources);
    for (i, src) in sources.iter().enumerate() {
        let meta = &preset.passes[i].meta;
        let stages = compile_pass(&semantics, i, src)?;
        let (mut fragment, mut vertex) = (stages.fragment, stages.vertex);
        let is_param = |n: &str| params.iter().any(|p| p.id.as_str() == n);
        let fm = meta.frame_count_mod;
        let fields = plan_fields([&fragment, &vertex], &src.path, fm, &is_param)?;
        let ensure: &[&str] = if needs_source(meta, i, i == last) {
            &["Source"]
        } else {
            &[]
        };
        let textures = rewrite_fragment(&mut fragment, &src.path, &fields, fm, &is_param, ensure)?;
        rewrite_vertex(&mut vertex, &src.path, &fields, fm, &is_param)?;
        let shader = format!("{effect}_pass{i}");
        let wgsl = combine(fragment, vertex, &src.source.vertex, &src.path)?;
        let (written_textures, written_fields) = written_names(&wgsl, &src.path)?;
        let wgsl = follow_renamed_textures(wgsl, &textures, &written_textures);
        let params = fields
            .names
            .iter()
            .zip(written_fields)
            .filter(|((n, _), _)| fields.params.contains(n))
            .map(|((n, _), w)| (n.clone(), w))
            .collect();
        let wgsl = format!(
            "{}{} (pass {i} of {})\n{wgsl}",
            crate::shader::GENERATED_FROM,
            src.path.display(),
            path.display()
        );
        shaders.push((shader.clone(), wgsl));
        plans.push(PassPlan {
            meta,
            name: src.source.name.as_ref().map(|n| n.to_string()),
            format: src.source.format,
            textures: textures.into_iter().zip(written_textures).collect(),
            params,
            shader,
        });
    }
    let luts: Vec<_> = preset.textures.iter().map(|t| t.meta.clone()).collect();
    let text = script(&ScriptInput {
        path,
        effect: &effect,
        passes: &plans,
        luts: &luts,
        parameters: &params,
    })?;
    let fx = store(path, &effect, &text, &shaders)?;
    Ok(Lowered {
        fx,
        luts: preset
            .textures
            .iter()
            .map(|t| (t.meta.name.to_string(), t.path.clone()))
            .collect(),
    })
}

/// The texture and uniform field names as the WGSL writer spelt them (it
/// escapes some: `PassOutput1` is written `PassOutput1_`), in declaration order.
fn written_names(wgsl: &str, path: &Path) -> Result<(Vec<String>, Vec<String>), SlangError> {
    let m = naga::front::wgsl::parse_str(wgsl).map_err(|e| SlangError::Unsupported {
        path: path.to_path_buf(),
        feature: "the translated WGSL".into(),
        why: e.emit_to_string(wgsl),
    })?;
    let mut textures = Vec::new();
    let mut fields = Vec::new();
    for (_, g) in m.global_variables.iter() {
        match &m.types[g.ty].inner {
            naga::TypeInner::Image { .. } => textures.push(g.name.clone().unwrap_or_default()),
            naga::TypeInner::Struct { members, .. } if g.space == naga::AddressSpace::Uniform => {
                fields = members
                    .iter()
                    .map(|x| x.name.clone().unwrap_or_default())
                    .collect();
            }
            _ => {}
        }
    }
    Ok((textures, fields))
}

/// The writer renames a texture whose name a local or argument also has
/// (`Source` → `Source_1`): its sampler and size field follow it.
fn follow_renamed_textures(mut wgsl: String, ir: &[String], written: &[String]) -> String {
    for (a, b) in ir.iter().zip(written) {
        let a = super::rewrite::wgsl_name(a);
        if a != *b {
            for suffix in ["_sampler", "_size_texel"] {
                wgsl = replace_word(&wgsl, &format!("{a}{suffix}"), &format!("{b}{suffix}"));
            }
        }
    }
    // The writer also folds `__` into `_`, so the sampler and size field of
    // `PassOutput1_` come out as `PassOutput1_sampler`: without this their input
    // would not be found, and the sampler would lose the preset's filter and wrap.
    for b in written.iter().filter(|b| b.ends_with('_')) {
        for suffix in ["_sampler", "_size_texel"] {
            wgsl = replace_word(
                &wgsl,
                &format!("{b}{}", &suffix[1..]),
                &format!("{b}{suffix}"),
            );
        }
    }
    wgsl
}

/// The preset's own values (`parameters = "a;b"`, `a = 0.5`) replace the
/// shaders' defaults.
fn with_preset_values(
    mut params: Vec<ShaderParameter>,
    preset: &ShaderPreset,
) -> Vec<ShaderParameter> {
    for p in &mut params {
        if let Some(v) = preset.parameters.iter().find(|v| v.name == p.id) {
            p.initial = v.value;
        }
    }
    params
}

/// `crt-easymode.slangp` → `crt_easymode`.
fn effect_name(path: &Path) -> String {
    let stem = path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("preset");
    let mut name: String = stem
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    if !name.starts_with(|c: char| c.is_ascii_alphabetic()) {
        name.insert_str(0, "slang_");
    }
    name
}

/// Writes the effect and its shaders into `<tmp>/fxgraph-slang/<hash>/`.
fn store(
    preset: &Path,
    effect: &str,
    text: &str,
    shaders: &[(String, String)],
) -> Result<PathBuf, SlangError> {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    text.hash(&mut h);
    shaders.hash(&mut h);
    let dir = std::env::temp_dir()
        .join("fxgraph-slang")
        .join(format!("{:016x}", h.finish()));
    let cache = |source| SlangError::Cache {
        path: preset.to_path_buf(),
        source,
    };
    std::fs::create_dir_all(&dir).map_err(cache)?;
    for (name, wgsl) in shaders {
        write_atomic(&dir.join(format!("{name}.wgsl")), wgsl).map_err(cache)?;
    }
    let fx = dir.join(format!("{effect}.fx"));
    write_atomic(&fx, text).map_err(cache)?;
    Ok(fx)
}

/// Another run may write the same (identical) files at the same time.
fn write_atomic(path: &Path, text: &str) -> std::io::Result<()> {
    let tmp = path.with_extension(format!("tmp{}", std::process::id()));
    std::fs::write(&tmp, text)?;
    std::fs::rename(&tmp, path)
}
