//! The wgpu texture format of each script format ([`wgpu_format`]): shared by
//! the transfers and the executor, so neither imports the other for it.

use crate::script::types::Format;

/// The wgpu format of a script format.
pub fn wgpu_format(f: Format) -> wgpu::TextureFormat {
    use wgpu::TextureFormat as T;
    match f {
        Format::Rgba8 => T::Rgba8Unorm,
        Format::Rgba8Srgb => T::Rgba8UnormSrgb,
        Format::Rgba16f => T::Rgba16Float,
        Format::Rgba32f => T::Rgba32Float,
        Format::Rgb10a2 => T::Rgb10a2Unorm,
        Format::R8 => T::R8Unorm,
        Format::R16f => T::R16Float,
        Format::R32f => T::R32Float,
        Format::Rg16f => T::Rg16Float,
        Format::Rg32f => T::Rg32Float,
    }
}

/// The WGSL texel format of a storage texture of `f` (`None`: no storage
/// texture of it is written here): the compute wrapper's target and the output
/// stand-in's conversion (gpu/executor).
pub fn wgsl_storage_format(f: wgpu::TextureFormat) -> Option<&'static str> {
    use wgpu::TextureFormat as T;
    Some(match f {
        T::Rgba8Unorm => "rgba8unorm",
        T::Rgba16Float => "rgba16float",
        T::Rgba32Float => "rgba32float",
        T::Rgb10a2Unorm => "rgb10a2unorm",
        T::R8Unorm => "r8unorm",
        T::R16Float => "r16float",
        T::R32Float => "r32float",
        T::Rg16Float => "rg16float",
        T::Rg32Float => "rg32float",
        _ => return None,
    })
}
