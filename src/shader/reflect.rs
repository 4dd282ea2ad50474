//! naga reflection of a pass shader and the checks of the script against it.

use crate::graph::PassNode;
use crate::script::types::{format_value, Value};
use crate::script::{Diagnostic, FileId, Span};
use crate::shader::wgsl_names::validation_diagnostic;
use naga::{ImageClass, ImageDimension, ScalarKind, TypeInner};

pub(crate) use super::uniforms::std_value;
pub use super::uniforms::{StdContext, StdValue, UniformField, UniformLayout, UniformSource};

/// The output of a compute-native pass: its one write-only
/// `texture_storage_2d<FORMAT, write>`.
#[derive(Debug, Clone)]
pub struct StorageOutput {
    pub name: String,
    pub binding: u32,
    /// The WGSL texel format (`rgba16float`, ...).
    pub format: naga::StorageFormat,
    pub span: Span,
}

/// A pass written as a `@compute` entry point (docs/shaders.md, "Compute
/// passes"): one invocation per output pixel (`workgroup[2]` per pixel when the
/// third size is above 1), `workgroup` invocations a group.
#[derive(Debug, Clone)]
pub struct ComputeNative {
    pub workgroup: [u32; 3],
    pub output: StorageOutput,
    /// The shader's `@fragment` entry point, where it has one too: the same
    /// pass drawn where the compute one cannot run (an sRGB or BGRA output, an
    /// adapter without that storage format).
    pub fragment: Option<String>,
}

impl ComputeNative {
    /// Whether each workgroup computes one output texel (`@workgroup_size(1, 1,
    /// Z)`: a reduction whose invocations share the work of one texel).
    pub fn per_texel(&self) -> bool {
        self.workgroup[0] * self.workgroup[1] == 1
    }
}

/// A `texture_2d<f32>` the script binds an input to, by name.
#[derive(Debug, Clone)]
pub struct TextureBinding {
    pub name: String,
    pub group: u32,
    pub binding: u32,
    pub span: Span,
}

/// A `sampler`: `<input>_sampler` takes that input's sampling, others the default.
#[derive(Debug, Clone)]
pub struct SamplerBinding {
    pub name: String,
    pub group: u32,
    pub binding: u32,
    pub span: Span,
}

/// Scalar/vector/matrix types a uniform field may have.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FieldType {
    F32(u8),
    I32(u8),
    U32(u8),
    Mat4,
}

impl FieldType {
    pub fn components(self) -> usize {
        match self {
            FieldType::F32(n) | FieldType::I32(n) | FieldType::U32(n) => n as usize,
            FieldType::Mat4 => 16,
        }
    }
    pub fn wgsl(self) -> String {
        let v = |n: u8, s: &str| {
            if n == 1 {
                s.to_string()
            } else {
                format!("vec{n}<{s}>")
            }
        };
        match self {
            FieldType::F32(n) => v(n, "f32"),
            FieldType::I32(n) => v(n, "i32"),
            FieldType::U32(n) => v(n, "u32"),
            FieldType::Mat4 => "mat4x4<f32>".into(),
        }
    }
}

/// A member of the shader's uniform struct.
#[derive(Debug, Clone)]
pub struct UniformMember {
    pub name: String,
    pub offset: u32,
    pub ty: FieldType,
    pub span: Span,
    /// From a `// @default(...)` annotation.
    pub default: Option<Value>,
    /// From a `// @range(min, max)` annotation.
    pub range: Option<(f64, f64)>,
    pub description: String,
}

impl UniformMember {
    /// The field of a pass's uniform layout this member becomes, filled from `source`.
    fn field(&self, source: UniformSource) -> UniformField {
        UniformField {
            name: self.name.clone(),
            offset: self.offset,
            ty: self.ty,
            source,
        }
    }
}

#[derive(Debug, Clone)]
pub struct UniformBlock {
    pub name: String,
    pub group: u32,
    pub binding: u32,
    pub size: u32,
    pub members: Vec<UniformMember>,
    pub span: Span,
}

/// Why a value does not fit a shader parameter (see [`check_member_value`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ValueMismatch {
    /// Wrong number of components, or a fraction (or a negative) for an integer field.
    #[error("the shader declares {expected}, found {found}")]
    WrongType { expected: String, found: String },
    /// Outside the field's `// @range(min, max)`.
    #[error("value {value} is out of range [{lo}, {hi}]")]
    OutOfRange { value: String, lo: f64, hi: f64 },
}

/// The type and range checks of a parameter value against the uniform member it
/// sets: the same checks for a value in the script, a `--set` and a value set
/// between frames (`Prepared::set_param`).
pub fn check_member_value(m: &UniformMember, value: &[f64]) -> Result<(), ValueMismatch> {
    let type_ok = value.len() == m.ty.components()
        && match m.ty {
            FieldType::F32(_) | FieldType::Mat4 => true,
            FieldType::I32(_) => value.iter().all(|x| x.fract() == 0.0),
            FieldType::U32(_) => value.iter().all(|x| x.fract() == 0.0 && *x >= 0.0),
        };
    if !type_ok {
        return Err(ValueMismatch::WrongType {
            expected: m.ty.wgsl(),
            found: format_value(value),
        });
    }
    if let Some((lo, hi)) = m.range {
        if value.iter().any(|&x| !(x >= lo && x <= hi)) {
            return Err(ValueMismatch::OutOfRange {
                value: format_value(value),
                lo,
                hi,
            });
        }
    }
    Ok(())
}

/// What a shader declares.
#[derive(Debug, Clone)]
pub struct Reflection {
    pub entry_point: String,
    /// A compute-native pass (`@compute` entry point and a storage output);
    /// `None` for a fragment pass.
    pub compute: Option<ComputeNative>,
    pub textures: Vec<TextureBinding>,
    pub samplers: Vec<SamplerBinding>,
    pub uniform: Option<UniformBlock>,
}

fn span(file: FileId, s: naga::Span) -> Span {
    match s.to_range() {
        Some(r) => Span::new(file, r.start, r.end),
        None => Span::new(file, 0, 0),
    }
}

/// Parse, validate and reflect preprocessed WGSL (`file` is its id in the source
/// map, so error spans point into it).
pub fn reflect(wgsl: &str, file: FileId) -> Result<Reflection, Vec<Diagnostic>> {
    let module = naga::front::wgsl::parse_str(wgsl).map_err(|e| {
        let mut d = Diagnostic::error(format!("WGSL: {}", e.message()));
        let mut first = true;
        for (s, label) in e.labels() {
            d = if first {
                d.at(span(file, s), label)
            } else {
                d.also(span(file, s), label)
            };
            first = false;
        }
        vec![d]
    })?;
    let mut validator = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    );
    if let Err(e) = validator.validate(&module) {
        return Err(vec![validation_diagnostic(
            &e,
            &module,
            wgsl,
            |s| Some(span(file, s)),
            Span::new(file, 0, 0),
        )]);
    }
    let mut diags = Vec::new();
    let fragments: Vec<_> = module
        .entry_points
        .iter()
        .filter(|e| e.stage == naga::ShaderStage::Fragment)
        .collect();
    let computes: Vec<_> = module
        .entry_points
        .iter()
        .filter(|e| e.stage == naga::ShaderStage::Compute)
        .collect();
    let native = match (fragments.as_slice(), computes.as_slice()) {
        ([] | [_], [one]) => Some(one),
        (_, []) => None,
        _ => {
            diags.push(
                Diagnostic::error(
                    "a pass shader has one `@fragment` entry point, one `@compute`, or one of each (the fragment one drawn where the compute one cannot run)",
                )
                .at(Span::new(file, 0, 0), ""),
            );
            return Err(diags);
        }
    };
    let entry_point = match fragments.as_slice() {
        _ if native.is_some() => native.map(|e| e.name.clone()).unwrap_or_default(),
        [one] => one.name.clone(),
        [] => {
            diags.push(Diagnostic::error("the shader has no `@fragment` entry point").at(Span::new(file, 0, 0), "expected `@fragment fn fs_main(@location(0) uv: vec2<f32>) -> @location(0) vec4<f32>`"));
            String::new()
        }
        many => {
            let names: Vec<&str> = many.iter().map(|e| e.name.as_str()).collect();
            diags.push(
                Diagnostic::error(format!(
                    "the shader has {} `@fragment` entry points ({}); a pass uses exactly one",
                    many.len(),
                    names.join(", ")
                ))
                .at(Span::new(file, 0, 0), ""),
            );
            String::new()
        }
    };
    // The fragment entry point: the pass's, or a compute pass's fallback.
    let fragment = match (native, fragments.as_slice()) {
        (Some(_), [one]) => Some(one.name.clone()),
        (Some(_), _) => None,
        (None, _) => Some(entry_point.clone()).filter(|e| !e.is_empty()),
    };
    if let Some(fragment) = &fragment {
        let vs = crate::shader::interface::fullscreen_outputs();
        let stage = "the pass's vertex stage";
        diags.extend(crate::shader::interface::check_fragment_inputs(
            &module, wgsl, file, fragment, vs, stage,
        ));
    }
    let mut textures = Vec::new();
    let mut samplers = Vec::new();
    let mut uniform = None;
    let mut outputs: Vec<StorageOutput> = Vec::new();
    for (h, gv) in module.global_variables.iter() {
        let gspan = span(file, module.global_variables.get_span(h));
        let name = gv.name.clone().unwrap_or_default();
        let Some(rb) = &gv.binding else { continue };
        match &module.types[gv.ty].inner {
            TypeInner::Image {
                dim: ImageDimension::D2,
                arrayed: false,
                class: ImageClass::Sampled { kind: ScalarKind::Float, multi: false },
            } => textures.push(TextureBinding { name, group: rb.group, binding: rb.binding, span: gspan }),
            TypeInner::Image {
                dim: ImageDimension::D2,
                arrayed: false,
                class: ImageClass::Storage { format, access },
            } if native.is_some() && *access == naga::StorageAccess::STORE => {
                outputs.push(StorageOutput { name, binding: rb.binding, format: *format, span: gspan })
            }
            TypeInner::Sampler { comparison: false } => samplers.push(SamplerBinding { name, group: rb.group, binding: rb.binding, span: gspan }),
            TypeInner::Struct { members, span: size } if gv.space == naga::AddressSpace::Uniform => {
                if uniform.is_some() {
                    diags.push(Diagnostic::error("a pass shader has at most one uniform buffer").at(gspan, "second uniform"));
                    continue;
                }
                let decl_span = module.types.get_span(gv.ty);
                let decl_text = decl_span.to_range().map(|r| &wgsl[r]).unwrap_or("");
                let decl_start = decl_span.to_range().map(|r| r.start).unwrap_or(0);
                let mut out = Vec::new();
                for m in members {
                    let mname = m.name.clone().unwrap_or_default();
                    let ty = field_type(&module, m.ty);
                    let (mspan, default, range, description) = member_annotations(decl_text, decl_start, &mname, file);
                    match ty {
                        Some(ty) => out.push(UniformMember { name: mname, offset: m.offset, ty, span: mspan.unwrap_or(gspan), default, range, description }),
                        None => diags.push(Diagnostic::error(format!("uniform field `{mname}` has an unsupported type")).at(mspan.unwrap_or(gspan), "use f32, i32, u32, their vectors, or mat4x4<f32>")),
                    }
                }
                uniform = Some(UniformBlock { name, group: rb.group, binding: rb.binding, size: *size, members: out, span: gspan });
            }
            _ => diags.push(
                Diagnostic::error(format!("unsupported resource `{name}` in a pass shader"))
                    .at(gspan, "a pass shader may declare texture_2d<f32>, sampler and one var<uniform> struct"),
            ),
        }
    }
    // One bind group keeps the layout simple: every resource in group 0.
    for (g, s) in textures
        .iter()
        .map(|t| (t.group, t.span))
        .chain(samplers.iter().map(|t| (t.group, t.span)))
        .chain(uniform.iter().map(|u| (u.group, u.span)))
    {
        if g != 0 {
            diags.push(
                Diagnostic::error("pass shader resources must be in `@group(0)`")
                    .at(s, "not in group 0"),
            );
        }
    }
    let compute = native.and_then(|ep| match outputs.as_slice() {
        [one] => Some(ComputeNative {
            workgroup: ep.workgroup_size,
            output: one.clone(),
            fragment: fragment.clone(),
        }),
        _ => {
            diags.push(
                Diagnostic::error(format!(
                    "a `@compute` pass shader writes its output to exactly one `texture_storage_2d<FORMAT, write>` ({} declared)",
                    outputs.len()
                ))
                .at(Span::new(file, 0, 0), "e.g. `@group(0) @binding(3) var out: texture_storage_2d<rgba16float, write>;`"),
            );
            None
        }
    });
    if diags.is_empty() {
        Ok(Reflection {
            entry_point,
            compute,
            textures,
            samplers,
            uniform,
        })
    } else {
        Err(diags)
    }
}

/// The parameter type of a struct member's WGSL type (f32, i32, u32, their
/// vectors, mat4x4<f32>), if it is one.
pub(crate) fn field_type(module: &naga::Module, ty: naga::Handle<naga::Type>) -> Option<FieldType> {
    match module.types[ty].inner {
        TypeInner::Scalar(s) => scalar_field(s, 1),
        TypeInner::Vector { size, scalar } => scalar_field(scalar, size as u8),
        TypeInner::Matrix {
            columns: naga::VectorSize::Quad,
            rows: naga::VectorSize::Quad,
            scalar,
        } if scalar.kind == ScalarKind::Float && scalar.width == 4 => Some(FieldType::Mat4),
        _ => None,
    }
}

fn scalar_field(s: naga::Scalar, n: u8) -> Option<FieldType> {
    match (s.kind, s.width) {
        (ScalarKind::Float, 4) => Some(FieldType::F32(n)),
        (ScalarKind::Sint, 4) => Some(FieldType::I32(n)),
        (ScalarKind::Uint, 4) => Some(FieldType::U32(n)),
        _ => None,
    }
}

/// The span of a struct member's declaration and its `// @default(..) @range(..) text` annotations.
/// Declaration span, `@default`, `@range` and description of a uniform member.
pub(crate) type MemberNotes = (Option<Span>, Option<Value>, Option<(f64, f64)>, String);

pub(crate) fn member_annotations(
    decl: &str,
    decl_start: usize,
    name: &str,
    file: FileId,
) -> MemberNotes {
    for (off, line) in crate::shader::preprocess::lines_with_offsets(decl) {
        let t = line.trim_start();
        let lead = line.len() - t.len();
        let matches = t
            .strip_prefix(name)
            .is_some_and(|r| r.trim_start().starts_with(':'));
        if matches {
            let code_len = t.find("//").unwrap_or(t.trim_end().len());
            let sp = Span::new(
                file,
                decl_start + off + lead,
                decl_start + off + lead + t[..code_len].trim_end().len(),
            );
            let mut default = None;
            let mut range = None;
            let mut desc = String::new();
            if let Some(c) = t.find("//") {
                let mut rest = t[c + 2..].trim();
                loop {
                    if let Some(r) = rest.strip_prefix("@default(") {
                        if let Some(end) = r.find(')') {
                            default = r[..end]
                                .split(',')
                                .map(|x| x.trim().parse::<f64>().ok())
                                .collect::<Option<Vec<_>>>();
                            rest = r[end + 1..].trim_start();
                            continue;
                        }
                    }
                    if let Some(r) = rest.strip_prefix("@range(") {
                        if let Some(end) = r.find(')') {
                            let v: Option<Vec<f64>> = r[..end]
                                .split(',')
                                .map(|x| x.trim().parse::<f64>().ok())
                                .collect();
                            if let Some([a, b]) = v.as_deref() {
                                range = Some((*a, *b));
                            }
                            rest = r[end + 1..].trim_start();
                            continue;
                        }
                    }
                    break;
                }
                desc = rest.to_string();
            }
            return (Some(sp), default, range, desc);
        }
    }
    (None, None, None, String::new())
}

/// Check a pass's inputs and parameters against its shader; build its uniform layout.
/// `shader_name` is how the shader is named in messages.
pub fn bind_pass(
    pass: &PassNode,
    refl: &Reflection,
    shader_name: &str,
) -> Result<UniformLayout, Vec<Diagnostic>> {
    let mut diags = Vec::new();
    let input_names: Vec<String> = pass.inputs.iter().map(|i| i.name.clone()).collect();
    for inp in &pass.inputs {
        if !refl.textures.iter().any(|t| t.name == inp.name) {
            let mut d = Diagnostic::error(format!(
                "shader `{shader_name}` has no texture input `{}`",
                inp.name
            ))
            .at(inp.span, "not declared by the shader");
            let names: Vec<&str> = refl.textures.iter().map(|t| t.name.as_str()).collect();
            d = match crate::script::ast::suggest(&inp.name, names.iter().copied()) {
                Some(s) => d.note(format!("did you mean `{s}`?")),
                None if names.is_empty() => d.note("the shader declares no `texture_2d<f32>`"),
                None => d.note(format!("its textures: {}", names.join(", "))),
            };
            diags.push(d);
        }
    }
    for t in &refl.textures {
        if !pass.inputs.iter().any(|i| i.name == t.name) {
            diags.push(
                Diagnostic::error(format!(
                    "pass `{}` does not bind the shader's texture `{}`",
                    pass.path, t.name
                ))
                .at(
                    pass.name_span,
                    format!("add `{} = IN` (or PASS.name, AUX.name)", t.name),
                )
                .also(t.span, "declared here"),
            );
        }
    }
    let mut layout = UniformLayout::default();
    let members: &[UniformMember] = refl
        .uniform
        .as_ref()
        .map(|u| u.members.as_slice())
        .unwrap_or(&[]);
    if let Some(u) = &refl.uniform {
        layout.size = u.size.max(16);
    }
    for p in &pass.params {
        let Some(m) = members.iter().find(|m| m.name == p.name) else {
            let mut d = Diagnostic::error(format!(
                "shader `{shader_name}` has no parameter `{}`",
                p.name
            ))
            .at(p.span, "not a field of the shader's uniform struct");
            let names: Vec<&str> = members
                .iter()
                .filter(|m| std_value(&m.name, &input_names).is_none())
                .map(|m| m.name.as_str())
                .collect();
            d = match crate::script::ast::suggest(&p.name, names.iter().copied()) {
                Some(s) => d.note(format!("did you mean `{s}`?")),
                None if names.is_empty() => d.note("the shader takes no parameters"),
                None => d.note(format!("its parameters: {}", names.join(", "))),
            };
            diags.push(d);
            continue;
        };
        if std_value(&m.name, &input_names).is_some() {
            diags.push(
                Diagnostic::error(format!(
                    "`{}` is a standard value set by the runtime",
                    p.name
                ))
                .at(p.span, "cannot be set")
                .also(m.span, "declared here"),
            );
            continue;
        }
        match check_member_value(m, &p.value) {
            Ok(()) => {}
            Err(ValueMismatch::WrongType { expected, found }) => {
                diags.push(
                    Diagnostic::error(format!(
                        "wrong type for `{}`: the shader declares {expected}, found {found}",
                        p.name,
                    ))
                    .at(p.span, format!("expected {expected}"))
                    .also(m.span, "declared here"),
                );
                continue;
            }
            Err(ValueMismatch::OutOfRange { value, lo, hi }) => {
                diags.push(
                    Diagnostic::error(format!(
                        "value {value} of `{}` is out of range [{}, {}]",
                        p.name,
                        format_value(&[lo]),
                        format_value(&[hi])
                    ))
                    .at(p.span, "out of range")
                    .also(m.span, "range declared here"),
                );
                continue;
            }
        }
        layout
            .fields
            .push(m.field(UniformSource::Param(p.value.clone())));
    }
    for m in members {
        if layout.fields.iter().any(|f| f.name == m.name)
            || pass.params.iter().any(|p| p.name == m.name)
        {
            continue;
        }
        if let Some((sv, types)) = std_value(&m.name, &input_names) {
            if !types.contains(&m.ty) {
                let want: Vec<String> = types.iter().map(|t| t.wgsl()).collect();
                diags.push(
                    Diagnostic::error(format!(
                        "standard value `{}` must be declared as {}",
                        m.name,
                        want.join(" or ")
                    ))
                    .at(m.span, "wrong type"),
                );
                continue;
            }
            layout.fields.push(m.field(UniformSource::Std(sv)));
        } else if let Some(def) = &m.default {
            if def.len() != m.ty.components() {
                diags.push(
                    Diagnostic::error(format!(
                        "`@default` of `{}` has {} values, the field has {}",
                        m.name,
                        def.len(),
                        m.ty.components()
                    ))
                    .at(m.span, "wrong default"),
                );
                continue;
            }
            layout
                .fields
                .push(m.field(UniformSource::Param(def.clone())));
        } else {
            diags.push(
                Diagnostic::error(format!(
                    "pass `{}` does not set the shader parameter `{}`",
                    pass.path, m.name
                ))
                .at(pass.name_span, format!("add `{} = ...`", m.name))
                .also(m.span, "declared here without a `// @default(...)`"),
            );
        }
    }
    if diags.is_empty() {
        Ok(layout)
    } else {
        Err(diags)
    }
}
