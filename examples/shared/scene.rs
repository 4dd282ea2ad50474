//! The examples' stand-in for an application's rendering: a dark gradient with
//! bright spots (what `glow` has something to do with), as RGBA f16 texels.

/// `width` x `height` RGBA16F texels (as bits), rows top to bottom.
pub fn gradient_with_spots(width: u32, height: u32) -> Vec<u16> {
    let mut texels = Vec::with_capacity((width * height * 4) as usize);
    for y in 0..height {
        for x in 0..width {
            let spot = ((x % 160) as f32 - 80.0).hypot((y % 120) as f32 - 60.0) < 6.0;
            let v = if spot {
                8.0
            } else {
                0.2 * x as f32 / width as f32
            };
            texels.extend([v, v * 0.8, 0.1, 1.0].map(|c| half::f16::from_f32(c).to_bits()));
        }
    }
    texels
}
