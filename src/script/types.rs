//! Value types of the language shared by the compiler and the runtime (no GPU types).

use serde::Serialize;
use std::fmt;

/// Pixel format of a pass output.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub enum Format {
    Rgba8,
    Rgba8Srgb,
    Rgba16f,
    Rgba32f,
    Rgb10a2,
    R8,
    R16f,
    R32f,
    Rg16f,
    Rg32f,
}

impl Format {
    pub const ALL: [Format; 10] = [
        Format::Rgba8,
        Format::Rgba8Srgb,
        Format::Rgba16f,
        Format::Rgba32f,
        Format::Rgb10a2,
        Format::R8,
        Format::R16f,
        Format::R32f,
        Format::Rg16f,
        Format::Rg32f,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Format::Rgba8 => "rgba8",
            Format::Rgba8Srgb => "rgba8-srgb",
            Format::Rgba16f => "rgba16f",
            Format::Rgba32f => "rgba32f",
            Format::Rgb10a2 => "rgb10a2",
            Format::R8 => "r8",
            Format::R16f => "r16f",
            Format::R32f => "r32f",
            Format::Rg16f => "rg16f",
            Format::Rg32f => "rg32f",
        }
    }

    pub fn from_name(s: &str) -> Option<Format> {
        Format::ALL.into_iter().find(|f| f.name() == s)
    }

    pub fn bytes_per_pixel(self) -> u64 {
        match self {
            Format::R8 => 1,
            Format::Rgba8 | Format::Rgba8Srgb | Format::Rgb10a2 | Format::R16f | Format::Rg16f => 4,
            Format::R32f => 4,
            Format::Rgba16f | Format::Rg32f => 8,
            Format::Rgba32f => 16,
        }
    }

    pub fn channels(self) -> u32 {
        match self {
            Format::R8 | Format::R16f | Format::R32f => 1,
            Format::Rg16f | Format::Rg32f => 2,
            _ => 4,
        }
    }

    /// Floating-point storage (values outside [0, 1] survive).
    pub fn is_float(self) -> bool {
        matches!(
            self,
            Format::Rgba16f
                | Format::Rgba32f
                | Format::R16f
                | Format::R32f
                | Format::Rg16f
                | Format::Rg32f
        )
    }

    /// Storage that encodes linear values as sRGB in hardware.
    pub fn is_srgb(self) -> bool {
        self == Format::Rgba8Srgb
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What the numbers in a texture mean.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum ColorSpace {
    /// Linear light (the default; what blending and filtering assume).
    Linear,
    /// sRGB-encoded (gamma) values.
    Srgb,
    /// The values as the effect's input stores them: `srgb` when the input is 8-bit
    /// sRGB (the stored codes, read and written raw: no decode or encode per texel),
    /// `linear` otherwise (float and `--assume-linear` inputs, no conversion). For
    /// filters meant for code values (deinterlacing, like yadif/bwdif on video) that
    /// must still keep float and HDR inputs exact. Resolved when the effect is
    /// planned ([`ColorSpace::resolve`]).
    Stored,
}

impl ColorSpace {
    pub fn name(self) -> &'static str {
        match self {
            ColorSpace::Linear => "linear",
            ColorSpace::Srgb => "srgb",
            ColorSpace::Stored => "stored",
        }
    }
    pub fn from_name(s: &str) -> Option<ColorSpace> {
        match s {
            "linear" => Some(ColorSpace::Linear),
            "srgb" => Some(ColorSpace::Srgb),
            "stored" => Some(ColorSpace::Stored),
            _ => None,
        }
    }

    /// `Stored` for an effect whose input has `input_format` and `input_space`:
    /// `Srgb` for an 8-bit sRGB input, `Linear` otherwise; other spaces as they are.
    pub fn resolve(self, input_format: Format, input_space: ColorSpace) -> ColorSpace {
        match self {
            ColorSpace::Stored
                if input_format == Format::Rgba8Srgb
                    || (input_format == Format::Rgba8 && input_space == ColorSpace::Srgb) =>
            {
                ColorSpace::Srgb
            }
            ColorSpace::Stored => ColorSpace::Linear,
            other => other,
        }
    }
}

impl fmt::Display for ColorSpace {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Default)]
pub enum Filter {
    #[default]
    Linear,
    Nearest,
}

impl Filter {
    pub fn from_name(s: &str) -> Option<Filter> {
        match s {
            "linear" => Some(Filter::Linear),
            "nearest" => Some(Filter::Nearest),
            _ => None,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Filter::Linear => "linear",
            Filter::Nearest => "nearest",
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Default)]
pub enum Wrap {
    #[default]
    Clamp,
    Repeat,
    Mirror,
    /// Transparent black outside `[0, 1]` (RetroArch's `clamp_to_border`).
    Border,
}

impl Wrap {
    pub fn from_name(s: &str) -> Option<Wrap> {
        match s {
            "clamp" => Some(Wrap::Clamp),
            "repeat" => Some(Wrap::Repeat),
            "mirror" => Some(Wrap::Mirror),
            "border" => Some(Wrap::Border),
            _ => None,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Wrap::Clamp => "clamp",
            Wrap::Repeat => "repeat",
            Wrap::Mirror => "mirror",
            Wrap::Border => "border",
        }
    }
}

/// How one input texture is sampled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Default)]
pub struct Sampling {
    pub filter: Filter,
    pub wrap_u: Wrap,
    pub wrap_v: Wrap,
    /// `NAME.MIPMAP = true`: the input is read with its full mip chain (made
    /// after its producer writes it, box-filtered), and `filter` is also the
    /// filter between mip levels. Without it, samples read level 0 only.
    pub mipmap: bool,
}

/// Auxiliary scene images the deferred renderer provides (G-buffer), plus any
/// user-supplied image (`fxrun --aux NAME=FILE`).
pub const AUX_GBUFFER_NAMES: [&str; 6] = [
    "depth", "normal", "position", "albedo", "material", "specular",
];

/// Type of an effect parameter.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub enum ParamType {
    Float,
    Int,
    Bool,
    Vec2,
    Vec3,
    Vec4,
    /// One of a list of words; the shader sees the index.
    Enum(Vec<String>),
}

impl ParamType {
    pub fn name(&self) -> &'static str {
        match self {
            ParamType::Float => "FLOAT",
            ParamType::Int => "INT",
            ParamType::Bool => "BOOL",
            ParamType::Vec2 => "VEC2",
            ParamType::Vec3 => "VEC3",
            ParamType::Vec4 => "VEC4",
            ParamType::Enum(_) => "ENUM",
        }
    }
    pub fn components(&self) -> usize {
        match self {
            ParamType::Vec2 => 2,
            ParamType::Vec3 => 3,
            ParamType::Vec4 => 4,
            _ => 1,
        }
    }
}

/// A parameter value: 1 to 4 numbers (booleans are 0/1, enums their index).
pub type Value = Vec<f64>;

/// Format a value the way it is written in a script.
pub fn format_value(v: &[f64]) -> String {
    let one = |x: f64| {
        if x.fract() == 0.0 && x.abs() < 1e15 {
            format!("{}", x as i64)
        } else {
            format!("{x}")
        }
    };
    if v.len() == 1 {
        one(v[0])
    } else {
        format!(
            "({})",
            v.iter().map(|&x| one(x)).collect::<Vec<_>>().join(", ")
        )
    }
}
