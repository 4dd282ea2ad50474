// Built-in (gpu/executor/stand_in.rs): a compute-native pass's values, stored
// in its own format, converted into a texture of the caller's output format,
// sRGB-encoded where the output is an sRGB image written in linear light. The
// executor fills in the storage format and the encoding.
@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst: texture_storage_2d<FXGRAPH_FORMAT, write>;
// FXGRAPH_SRGB_ENCODE

@compute @workgroup_size(8, 8, 1)
fn fx_cs_convert(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(dst);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    textureStore(dst, id.xy, FXGRAPH_ENCODE(textureLoad(src, id.xy, 0)));
}
