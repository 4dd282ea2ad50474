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
