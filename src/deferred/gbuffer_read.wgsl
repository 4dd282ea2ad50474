// The G-buffer and light buffers, read with textureLoad at the pixel.
@group(1) @binding(0) var t_depth: texture_depth_2d;
// rgb albedo (sRGB storage, linear when loaded), a = material id / 255
@group(1) @binding(1) var t_albedo: texture_2d<f32>;
// rg encoded view-space normal, b = specular k_s
@group(1) @binding(2) var t_gnormal: texture_2d<f32>;
@group(1) @binding(3) var t_diffuse: texture_2d<f32>;
@group(1) @binding(4) var t_specular: texture_2d<f32>;
