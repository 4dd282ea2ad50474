//! naga reflection of a pass shader (its entry points, resources and uniform
//! struct) and the checks of the script against it (`reflect/bind.rs`).

use crate::script::types::{format_value, Value};
use crate::script::{Diagnostic, FileId, Span};
use crate::shader::wgsl_names::validation_diagnostic;
use naga::{ImageClass, ImageDimension, ScalarKind, TypeInner};

mod bind;
mod execution_line;

pub(crate) use super::uniforms::std_value;
pub use super::uniforms::{StdContext, StdValue, UniformField, UniformLayout, UniformSource};
pub use bind::bind_pass;

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
    /// The shader's `// @execution(compute)` line: its compute entry point
    /// runs under compute execution only, and fragment execution draws its
    /// fragment one (a pass whose staging does not pay on CPU adapters).
    pub compute_execution_only: bool,
}

impl ComputeNative {
    /// Whether several invocations share the work of each output texel (a third
    /// workgroup size above 1: a reduction, `@workgroup_size(1, 1, Z)`, or
    /// motion_blur's tile maximum, `(1, 8, 32)`). Under fragment execution such a
    /// pass draws its `@fragment` entry point: on lavapipe such a dispatch costs
    /// more than the fragment pass over the same footprint.
    pub fn lanes_per_texel(&self) -> bool {
        self.workgroup[2] > 1
    }

    /// Whether fragment execution draws the fragment entry point instead of
    /// dispatching the compute one: passes with several lanes per texel
    /// ([`ComputeNative::lanes_per_texel`]) and shaders marked
    /// `// @execution(compute)`.
    pub fn drawn_under_fragment_execution(&self) -> bool {
        self.fragment.is_some() && (self.lanes_per_texel() || self.compute_execution_only)
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
    let module = parse_and_validate(wgsl, file)?;
    let mut diags = Vec::new();
    let entries = entry_points(&module, file, &mut diags)?;
    if let Some(fragment) = &entries.fragment {
        let vs = crate::shader::interface::fullscreen_outputs();
        let stage = "the pass's vertex stage";
        diags.extend(crate::shader::interface::check_fragment_inputs(
            &module, wgsl, file, fragment, vs, stage,
        ));
    }
    let source = ShaderSource {
        module: &module,
        wgsl,
        file,
    };
    let resources = source.resources(entries.native.is_some(), &mut diags);
    check_group_zero(&resources, &mut diags);
    let mut compute = entries.native.and_then(|ep| {
        compute_native(
            ep,
            &resources.outputs,
            entries.fragment.clone(),
            file,
            &mut diags,
        )
    });
    if let Some(native) = &mut compute {
        match execution_line::compute_execution_only(wgsl, file, native) {
            Ok(only) => native.compute_execution_only = only,
            Err(d) => diags.push(d),
        }
    }
    if diags.is_empty() {
        Ok(Reflection {
            entry_point: entries.entry_point,
            compute,
            textures: resources.textures,
            samplers: resources.samplers,
            uniform: resources.uniform,
        })
    } else {
        Err(diags)
    }
}

/// The naga module of `wgsl`, or its parse or validation error.
fn parse_and_validate(wgsl: &str, file: FileId) -> Result<naga::Module, Vec<Diagnostic>> {
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
    Ok(module)
}

/// The entry points a pass shader runs.
struct EntryPoints<'m> {
    /// The `@compute` entry point of a compute-native pass.
    native: Option<&'m naga::EntryPoint>,
    /// The pass's entry point (the compute one for a compute-native pass).
    entry_point: String,
    /// The fragment entry point: the pass's, or a compute pass's fallback.
    fragment: Option<String>,
}

/// The entry points of `module`: one `@fragment`, one `@compute`, or one of
/// each. Errors that leave nothing to check return at once.
fn entry_points<'m>(
    module: &'m naga::Module,
    file: FileId,
    diags: &mut Vec<Diagnostic>,
) -> Result<EntryPoints<'m>, Vec<Diagnostic>> {
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
        ([] | [_], [one]) => Some(*one),
        (_, []) => None,
        _ => {
            diags.push(
                Diagnostic::error(
                    "a pass shader has one `@fragment` entry point, one `@compute`, or one of each (the fragment one drawn where the compute one cannot run)",
                )
                .at(Span::new(file, 0, 0), ""),
            );
            return Err(std::mem::take(diags));
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
    let fragment = match (native, fragments.as_slice()) {
        (Some(_), [one]) => Some(one.name.clone()),
        (Some(_), _) => None,
        (None, _) => Some(entry_point.clone()).filter(|e| !e.is_empty()),
    };
    Ok(EntryPoints {
        native,
        entry_point,
        fragment,
    })
}

/// The resources a pass shader declares.
struct Resources {
    textures: Vec<TextureBinding>,
    samplers: Vec<SamplerBinding>,
    uniform: Option<UniformBlock>,
    /// Storage textures written by a compute-native pass.
    outputs: Vec<StorageOutput>,
}

/// A validated pass shader: the module, its text and its file.
struct ShaderSource<'a> {
    module: &'a naga::Module,
    wgsl: &'a str,
    file: FileId,
}

impl ShaderSource<'_> {
    /// Every bound global variable, by its type (storage outputs only in a
    /// compute-native pass).
    fn resources(&self, native: bool, diags: &mut Vec<Diagnostic>) -> Resources {
        let (module, file) = (self.module, self.file);
        let mut r = Resources {
            textures: Vec::new(),
            samplers: Vec::new(),
            uniform: None,
            outputs: Vec::new(),
        };
        for (h, gv) in module.global_variables.iter() {
            let gspan = span(file, module.global_variables.get_span(h));
            let name = gv.name.clone().unwrap_or_default();
            let Some(rb) = &gv.binding else { continue };
            match &module.types[gv.ty].inner {
                TypeInner::Image {
                    dim: ImageDimension::D2,
                    arrayed: false,
                    class: ImageClass::Sampled { kind: ScalarKind::Float, multi: false },
                } => r.textures.push(TextureBinding { name, group: rb.group, binding: rb.binding, span: gspan }),
                TypeInner::Image {
                    dim: ImageDimension::D2,
                    arrayed: false,
                    class: ImageClass::Storage { format, access },
                } if native && *access == naga::StorageAccess::STORE => {
                    r.outputs.push(StorageOutput { name, binding: rb.binding, format: *format, span: gspan })
                }
                TypeInner::Sampler { comparison: false } => r.samplers.push(SamplerBinding { name, group: rb.group, binding: rb.binding, span: gspan }),
                TypeInner::Struct { members, span: size } if gv.space == naga::AddressSpace::Uniform => {
                    if r.uniform.is_some() {
                        diags.push(Diagnostic::error("a pass shader has at most one uniform buffer").at(gspan, "second uniform"));
                        continue;
                    }
                    let members = self.uniform_members(gv.ty, members, gspan, diags);
                    r.uniform = Some(UniformBlock { name, group: rb.group, binding: rb.binding, size: *size, members, span: gspan });
                }
                _ => diags.push(
                    Diagnostic::error(format!("unsupported resource `{name}` in a pass shader"))
                        .at(gspan, "a pass shader may declare texture_2d<f32>, sampler and one var<uniform> struct"),
                ),
            }
        }
        r
    }

    /// The members of the uniform struct `ty` (declared by the variable at
    /// `gspan`), with their annotations; unsupported types are errors.
    fn uniform_members(
        &self,
        ty: naga::Handle<naga::Type>,
        members: &[naga::StructMember],
        gspan: Span,
        diags: &mut Vec<Diagnostic>,
    ) -> Vec<UniformMember> {
        let decl_span = self.module.types.get_span(ty);
        let decl_text = decl_span.to_range().map(|r| &self.wgsl[r]).unwrap_or("");
        let decl_start = decl_span.to_range().map(|r| r.start).unwrap_or(0);
        let mut out = Vec::new();
        for m in members {
            let mname = m.name.clone().unwrap_or_default();
            let ty = field_type(self.module, m.ty);
            let (mspan, default, range, description) =
                member_annotations(decl_text, decl_start, &mname, self.file);
            match ty {
                Some(ty) => out.push(UniformMember {
                    name: mname,
                    offset: m.offset,
                    ty,
                    span: mspan.unwrap_or(gspan),
                    default,
                    range,
                    description,
                }),
                None => diags.push(
                    Diagnostic::error(format!("uniform field `{mname}` has an unsupported type"))
                        .at(
                            mspan.unwrap_or(gspan),
                            "use f32, i32, u32, their vectors, or mat4x4<f32>",
                        ),
                ),
            }
        }
        out
    }
}

/// One bind group keeps the layout simple: every resource in group 0.
fn check_group_zero(r: &Resources, diags: &mut Vec<Diagnostic>) {
    for (g, s) in r
        .textures
        .iter()
        .map(|t| (t.group, t.span))
        .chain(r.samplers.iter().map(|t| (t.group, t.span)))
        .chain(r.uniform.iter().map(|u| (u.group, u.span)))
    {
        if g != 0 {
            diags.push(
                Diagnostic::error("pass shader resources must be in `@group(0)`")
                    .at(s, "not in group 0"),
            );
        }
    }
}

/// The compute-native pass of entry point `ep`: it writes exactly one storage
/// texture.
fn compute_native(
    ep: &naga::EntryPoint,
    outputs: &[StorageOutput],
    fragment: Option<String>,
    file: FileId,
    diags: &mut Vec<Diagnostic>,
) -> Option<ComputeNative> {
    match outputs {
        [one] => Some(ComputeNative {
            workgroup: ep.workgroup_size,
            output: one.clone(),
            fragment,
            compute_execution_only: false,
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
