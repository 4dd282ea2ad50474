// A type error: `&` between an i32 and a struct (issue 29: the diagnostic named the
// struct by naga's internal dump, `Struct { members: [StructMember { ...`).
struct Pencil {
    w: f32,
    strength: vec2<f32>,
}
@group(0) @binding(0) var img: texture_2d<f32>;
@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(img, vec2<i32>(pos.xy), 0);
    var p: Pencil;
    p.w = c.r;
    let steps: i32 = 3;
    let k = steps & p;
    return vec4<f32>(c.rgb, 1.0);
}
