//! One pass of a preset through the librashader crates: preprocess the `.slang`
//! file (includes, pragmas), compile its GLSL to SPIR-V (glslang), check its
//! semantics against the preset (librashader-reflect) and bring both stages into
//! naga's IR. Every failure becomes a [`SlangError`] naming the file.

use super::error::{FailureClass, SlangError};
use crate::unwind::catch_quiet;
use librashader_preprocess::{ShaderParameter, ShaderSource};
use librashader_presets::{ShaderFeatures, ShaderPreset};
use librashader_reflect::back::targets::WGSL;
use librashader_reflect::back::{CompileShader, FromCompilation};
use librashader_reflect::error::{SemanticsErrorKind, ShaderCompileError, ShaderReflectError};
use librashader_reflect::front::{Glslang, ShaderInputCompiler};
use librashader_reflect::reflect::naga::NagaLoweringOptions;
use librashader_reflect::reflect::semantics::{
    Semantic, ShaderSemantics, TextureSemantics, UniformSemantic, UniqueSemantics,
};
use librashader_reflect::reflect::ReflectShader;
use std::path::{Path, PathBuf};

/// A pass's shader source, preprocessed.
pub struct Source {
    pub path: PathBuf,
    pub source: ShaderSource,
}

/// A pass's two stages in naga's IR, after librashader's lowering (push
/// constants as a second uniform block, samplers split from their textures into
/// bind group 1).
pub struct Stages {
    pub vertex: naga::Module,
    pub fragment: naga::Module,
}

/// Preprocesses the shader of pass `path`.
pub fn load_source(path: &Path) -> Result<Source, SlangError> {
    let loaded =
        catch_quiet(|| ShaderSource::load(path, ShaderFeatures::NONE)).map_err(|panic| {
            SlangError::Preprocess {
                path: path.to_path_buf(),
                message: format!("the preprocessor failed: {panic}"),
            }
        })?;
    let mut source = loaded.map_err(|e| SlangError::Preprocess {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    (source.vertex, source.fragment) =
        super::varyings::split_matrix_varyings(&source.vertex, &source.fragment);
    let shader = path.file_name().and_then(|f| f.to_str()).unwrap_or("");
    source.vertex = super::line_markers::corrected_line_markers(&source.vertex, shader);
    source.fragment = super::line_markers::corrected_line_markers(&source.fragment, shader);
    source.vertex = super::builtins::with_replaced_builtins(std::mem::take(&mut source.vertex));
    source.fragment = super::builtins::with_replaced_builtins(std::mem::take(&mut source.fragment));
    Ok(Source {
        path: path.to_path_buf(),
        source,
    })
}

/// The parameters of all passes, by id (the first declaration of an id wins, as
/// in RetroArch).
pub fn parameters(sources: &[Source]) -> Vec<ShaderParameter> {
    let mut out: Vec<ShaderParameter> = Vec::new();
    for s in sources {
        let mut own: Vec<&ShaderParameter> = s.source.parameters.values().collect();
        own.sort_by(|a, b| a.id.cmp(&b.id));
        for p in own {
            if !out.iter().any(|q| q.id == p.id) {
                out.push(p.clone());
            }
        }
    }
    out
}

/// The semantics every pass of `preset` may read, as librashader's runtime
/// builds them for the whole chain (`compile_preset_passes`): every pass's
/// `#pragma parameter`s; every pass's alias and `#pragma name`, as its output
/// (`NAME`, `NAMESize`) and feedback (`NAMEFeedback`, `NAMEFeedbackSize`); the
/// LUTs (`NAME`, `NAMESize`). librashader's reflection-only helper
/// (`ShaderSemantics::create_pass_semantics`) knows only the pass's own alias,
/// so a pass reading an earlier one by its alias (NIS's scaler reads
/// `NISCoef`) failed as an unknown semantic.
pub fn preset_semantics(preset: &ShaderPreset, sources: &[Source]) -> ShaderSemantics {
    let mut semantics = ShaderSemantics {
        uniform_semantics: Default::default(),
        texture_semantics: Default::default(),
    };
    for s in sources {
        for p in s.source.parameters.values() {
            let parameter = UniqueSemantics::FloatParameter;
            let unique = UniformSemantic::Unique(Semantic {
                semantics: parameter,
                index: (),
            });
            semantics.uniform_semantics.insert(p.id.clone(), unique);
        }
    }
    for (pass, s) in preset.passes.iter().zip(sources) {
        for name in [pass.meta.alias.as_ref(), s.source.name.as_ref()]
            .into_iter()
            .flatten()
        {
            if !name.trim().is_empty() {
                insert_texture(
                    &mut semantics,
                    name,
                    TextureSemantics::PassOutput,
                    pass.meta.id as usize,
                    "",
                );
                insert_texture(
                    &mut semantics,
                    name,
                    TextureSemantics::PassFeedback,
                    pass.meta.id as usize,
                    "Feedback",
                );
            }
        }
    }
    for (index, lut) in preset.textures.iter().enumerate() {
        insert_texture(
            &mut semantics,
            &lut.meta.name,
            TextureSemantics::User,
            index,
            "",
        );
    }
    semantics
}

/// `NAME{suffix}` as texture `kind` number `index`, and `NAME{suffix}Size` as its size.
fn insert_texture(
    semantics: &mut ShaderSemantics,
    name: &str,
    kind: TextureSemantics,
    index: usize,
    suffix: &str,
) {
    let texture = Semantic {
        semantics: kind,
        index,
    };
    semantics
        .texture_semantics
        .insert(format!("{name}{suffix}").as_str().into(), texture);
    semantics.uniform_semantics.insert(
        format!("{name}{suffix}Size").as_str().into(),
        UniformSemantic::Texture(texture),
    );
}

/// Compiles pass `index` of a preset to naga modules, with the preset's
/// `semantics` ([`preset_semantics`]).
pub fn compile_pass(
    semantics: &ShaderSemantics,
    index: usize,
    src: &Source,
) -> Result<Stages, SlangError> {
    let path = &src.path;
    let spirv = catch_quiet(|| Glslang::compile(&src.source).map_err(|e| compile_error(path, e)))
        .map_err(|panic| glsl_error(path, &format!("glslang failed: {panic}")))??;
    let semantics = semantics.clone();
    let outcome = catch_quiet(move || -> Result<Stages, SlangError> {
        let mut backend = WGSL::from_compilation(spirv).map_err(|e| reflect_error(path, e))?;
        backend
            .reflect(index, &semantics)
            .map_err(|e| reflect_error(path, e))?;
        let out = backend
            .compile(NagaLoweringOptions {
                write_pcb_as_ubo: true,
                sampler_bind_group: 1,
                suppress_derivative_uniformity: false,
            })
            .map_err(|e| compile_error(path, e))?;
        Ok(Stages {
            vertex: out.context.vertex,
            fragment: out.context.fragment,
        })
    });
    outcome.map_err(|panic| translate_error(path, &panic))?
}

fn glsl_error(path: &Path, message: &str) -> SlangError {
    SlangError::Glsl {
        path: path.to_path_buf(),
        line: None,
        message: message.to_string(),
    }
}

fn translate_error(path: &Path, message: &str) -> SlangError {
    SlangError::Translate {
        path: path.to_path_buf(),
        class: FailureClass::of(message),
        message: message.to_string(),
    }
}

/// A compiler error; glslang's `ERROR: FILE:LINE: text` becomes `path:line`.
fn compile_error(path: &Path, e: ShaderCompileError) -> SlangError {
    match e {
        ShaderCompileError::GlslangError(g) => {
            let text = g.to_string();
            match glslang_location(&text) {
                Some((file, line, message)) => SlangError::Glsl {
                    path: locate_file(path, &file),
                    line: Some(line),
                    message,
                },
                None => glsl_error(path, text.trim()),
            }
        }
        other => translate_error(path, &with_causes(&other)),
    }
}

/// An error and its causes, `: `-separated (naga's validation errors say the
/// function first and what is wrong in it last).
fn with_causes(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        text.push_str(": ");
        text.push_str(&c.to_string());
        cause = c.source();
    }
    text
}

fn reflect_error(path: &Path, e: ShaderReflectError) -> SlangError {
    use SemanticsErrorKind::UnknownSemantics;
    match e {
        ShaderReflectError::FragmentSemanticError(UnknownSemantics(name))
        | ShaderReflectError::VertexSemanticError(UnknownSemantics(name)) => SlangError::Semantic {
            path: path.to_path_buf(),
            name,
        },
        other => translate_error(path, &with_causes(&other)),
    }
}

/// The first `ERROR: FILE:LINE: message` of a glslang log.
fn glslang_location(log: &str) -> Option<(String, u32, String)> {
    for l in log.lines() {
        let Some(at) = l.find("ERROR: ") else {
            continue;
        };
        let rest = &l[at + "ERROR: ".len()..];
        let mut parts = rest.splitn(3, ':');
        let (file, line, message) = (parts.next()?, parts.next()?, parts.next()?);
        if let Ok(line) = line.trim().parse::<u32>() {
            let file = file.trim().trim_matches('"').to_string();
            return Some((file, line, message.trim().to_string()));
        }
    }
    None
}

/// `#line` markers name files without their folder: the pass file itself, or a
/// file it includes (searched below the pass's folder and its parents).
fn locate_file(pass: &Path, name: &str) -> PathBuf {
    if pass.file_name().and_then(|f| f.to_str()) == Some(name) || name.is_empty() {
        return pass.to_path_buf();
    }
    let mut dir = pass.parent();
    for _ in 0..4 {
        let Some(d) = dir else { break };
        if let Some(found) = find_below(d, name, 3) {
            return found;
        }
        dir = d.parent();
    }
    PathBuf::from(name)
}

fn find_below(dir: &Path, name: &str, depth: u32) -> Option<PathBuf> {
    let direct = dir.join(name);
    if direct.is_file() {
        return Some(direct);
    }
    if depth == 0 {
        return None;
    }
    let entries = std::fs::read_dir(dir).ok()?;
    entries
        .flatten()
        .filter(|e| e.path().is_dir())
        .find_map(|e| find_below(&e.path(), name, depth - 1))
}

#[cfg(test)]
mod tests {
    use super::glslang_location;

    #[test]
    fn glslang_locations_are_found() {
        let log = "compile failed\nERROR: blur.slang:42: 'foo' : undeclared identifier\n";
        assert_eq!(
            glslang_location(log),
            Some((
                "blur.slang".into(),
                42,
                "'foo' : undeclared identifier".into()
            ))
        );
    }
}
