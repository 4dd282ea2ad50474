//! A bare file name (`mine.fx`) resolves like `./mine.fx` for every option of
//! `fxrun` that takes a file: `--materials` (and the shaders and textures the
//! material file names next to it), `--aux`, `--scene` (and the files a glTF
//! names), `--gbuffer`, effect files (and their shaders and `INCLUDE`s). Each test
//! runs `fxrun` in a folder holding the files, once with the bare names and once
//! with `./` names, and requires both to succeed with byte-identical outputs.
//! (The folder of a bare name is the empty path, which `canonicalize` refuses: a
//! material file's shaders were not found that way.)

use crate::common;

use common::cli::{code, fxrun_in, save, stderr, write};
use std::path::Path;

/// Runs `fxrun LINE` in `dir` with each `{NAME}` of the line given as `NAME`, then
/// as `./NAME`; both must exit 0 and write identical files `outputs` (removed
/// between the runs).
fn same_with_dot(dir: &Path, line: &str, outputs: &[&str]) {
    let bare = line.replace(['{', '}'], "");
    let dotted = line.replace('{', "./").replace('}', "");
    let mut results = Vec::new();
    for line in [bare, dotted] {
        let args: Vec<&str> = line.split_whitespace().collect();
        for o in outputs {
            let p = dir.join(o);
            if p.is_dir() {
                std::fs::remove_dir_all(&p).unwrap();
            } else {
                let _ = std::fs::remove_file(&p);
            }
        }
        let out = fxrun_in(dir, &args);
        assert_eq!(code(&out), 0, "fxrun {args:?}:\n{}", stderr(&out));
        let mut files = Vec::new();
        for o in outputs {
            let p = dir.join(o);
            if p.is_dir() {
                let mut names: Vec<_> = std::fs::read_dir(&p)
                    .unwrap()
                    .map(|e| e.unwrap().path())
                    .collect();
                names.sort();
                assert!(!names.is_empty(), "{o}: empty folder");
                for n in names {
                    files.push((n.clone(), std::fs::read(n).unwrap()));
                }
            } else {
                files.push((p.clone(), std::fs::read(&p).unwrap()));
            }
        }
        results.push(files);
    }
    assert_eq!(results[0].len(), results[1].len());
    for ((name, a), (_, b)) in results[0].iter().zip(&results[1]) {
        assert!(
            a == b,
            "{}: differs between bare and ./ names",
            name.display()
        );
    }
}

/// `--scene builtin:room --materials FILE --material '*=DEF'`, FILE holding
/// `text`, with FILE bare and with `./`: the same image.
fn room_with_materials(dir: &Path, (file, text): (&str, &str), def: &str) {
    write(dir, file, text);
    let line = format!(
        "--materials {{{file}}} --scene builtin:room --size 64x48 --material *={def} -o out.png"
    );
    same_with_dot(dir, &line, &["out.png"]);
}

/// A surface shader that is flat colour, and a half-Lambert lighting shader.
fn write_material_shaders(dir: &Path) {
    write(
        dir,
        "flat.wgsl",
        "struct SurfaceParams { color: vec4<f32>, }\n\
         @group(2) @binding(0) var<uniform> params: SurfaceParams;\n\
         fn surface(in: SurfaceInput) -> SurfaceOutput {\n\
         \x20   var out: SurfaceOutput;\n\
         \x20   out.diffuse = params.color.rgb;\n\
         \x20   out.specular = vec3<f32>(0.04);\n\
         \x20   out.roughness = 0.5;\n\
         \x20   out.alpha = 1.0;\n\
         \x20   out.normal = in.normal;\n\
         \x20   out.emission = vec3<f32>(0.0);\n\
         \x20   out.occlusion = 1.0;\n\
         \x20   return out;\n\
         }\n",
    );
    write(
        dir,
        "halflambert.wgsl",
        "fn lighting(in: LightingInput) -> LightingOutput {\n\
         \x20   let h = dot(in.normal, in.light_dir) * 0.5 + 0.5;\n\
         \x20   return LightingOutput(in.light * h * h / 3.14159265, vec3<f32>(0.0));\n\
         }\n",
    );
}

/// The case of the issue: `--materials mine.fx` with the material's shaders next
/// to it, in the current folder.
#[test]
fn materials_file_by_bare_name_finds_its_shaders() {
    let dir = tempfile::tempdir().unwrap();
    write_material_shaders(dir.path());
    let mine = "MATERIAL.mine = {\n    SURFACE = SHADER.flat { color = (0.8, 0.3, 0.2, 1) }\n    LIGHTING = SHADER.halflambert\n}\n";
    room_with_materials(dir.path(), ("mine.fx", mine), "mine");
}

/// A texture a material names (`base_color_map = "tex.png"`) is next to the
/// material file given by its bare name.
#[test]
fn material_textures_resolve_next_to_a_bare_material_file() {
    let dir = tempfile::tempdir().unwrap();
    let tex = common::pattern_u8(16, 16);
    save(&dir.path().join("tex.png"), &tex);
    let textured = "MATERIAL.t = {\n    SURFACE = SHADER.standard { base_color_map = \"tex.png\" }\n    LIGHTING = SHADER.lambert\n}\n";
    room_with_materials(dir.path(), ("textured.fx", textured), "t");
}

/// `--aux background=bg.png`.
#[test]
fn aux_image_by_bare_name() {
    let dir = tempfile::tempdir().unwrap();
    for (name, img) in [
        ("in.png", common::pattern_u8(24, 16)),
        (
            "bg.png",
            common::image_u8(24, 16, |x, y| [x as u8 * 9, y as u8 * 13, 90, 255]),
        ),
    ] {
        save(&dir.path().join(name), &img);
    }
    same_with_dot(
        dir.path(),
        "chroma_composite -i {in.png} --aux background={bg.png} -o out.png",
        &["out.png"],
    );
}

/// `--scene spheres.gltf` whose buffer is a file next to it (`"uri": "spheres.bin"`).
#[test]
fn scene_by_bare_name_finds_its_buffer() {
    let dir = tempfile::tempdir().unwrap();
    let mut json = common::gltf_gen::spheres_gltf_json(&Default::default());
    // The embedded buffer moved to a file of its own.
    let uri = json["buffers"][0]["uri"].as_str().unwrap().to_string();
    let data = common::gltf_gen::base64_decode(uri.split_once(',').unwrap().1);
    std::fs::write(dir.path().join("spheres.bin"), data).unwrap();
    json["buffers"][0]["uri"] = "spheres.bin".into();
    common::gltf_gen::write_gltf(dir.path(), "spheres.gltf", &json);
    same_with_dot(
        dir.path(),
        "--scene {spheres.gltf} --size 64x48 -o out.png",
        &["out.png"],
    );
}

/// `--gbuffer gb`: a folder by its bare name, created in the current folder.
#[test]
fn gbuffer_folder_by_bare_name() {
    let dir = tempfile::tempdir().unwrap();
    same_with_dot(
        dir.path(),
        "--scene builtin:room --size 64x48 --gbuffer {gb}",
        &["gb"],
    );
}

/// An effect file by its bare name, with its shader and an `INCLUDE`d file next to it.
#[test]
fn effect_file_by_bare_name_finds_its_shader_and_include() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "tint.wgsl",
        "@group(0) @binding(0) var img: texture_2d<f32>;\n\
         @fragment\n\
         fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {\n\
         \x20   let c = textureLoad(img, vec2<i32>(pos.xy), 0);\n\
         \x20   return vec4<f32>(c.r, c.g * 0.5, c.b, c.a);\n\
         }\n",
    );
    write(
        dir.path(),
        "inner.fx",
        "EFFECT.inner = { PASS = { t = SHADER.tint { img = IN } } OUT = t }\n",
    );
    write(
        dir.path(),
        "mine.fx",
        "INCLUDE \"inner.fx\"\nEFFECT.mine = { PASS = { a = EFFECT.inner { IN = IN } b = SHADER.tint { img = PASS.a } } OUT = b }\n",
    );
    let img = common::pattern_u8(20, 12);
    save(&dir.path().join("in.png"), &img);
    same_with_dot(dir.path(), "{mine.fx} -i {in.png} -o out.png", &["out.png"]);
}
