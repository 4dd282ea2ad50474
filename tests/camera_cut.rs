//! Camera cuts (docs/renderer.md, "Camera cuts"): a generated glTF whose camera
//! node jumps with a STEP key at 1 s from a view of a red triangle to the same
//! view of a blue one, rendered through `taa` at 30 fps. Frame 30 (t = 1 s) starts the new
//! shot: taa drops its history there, so the frame of the sequence (with five
//! frames of the old shot in its history) is byte-identical to frame 30 rendered
//! alone without any history (`--warmup 0`): no ghost of the previous view. The
//! control: frame 29, inside the first shot, differs from itself rendered alone
//! (the history does change taa's output).

use crate::common;

use common::anim_gltf::{node_scene, write, ChannelSpec, GltfBuilder};
use common::cli::{code, fxrun, stderr};
use serde_json::json;
use std::path::Path;

/// Triangle A (node 0, red) at the origin, triangle B (node 1, blue) the same
/// 20 units along x; the camera (node 2) looks at A until 1 s, then jumps
/// (STEP) to the same place relative to B. Both shots show a triangle at the
/// same pixels and depth: only the colour tells them apart, so nothing but the
/// cut itself (not the reprojection's out-of-frame or disocclusion tests) can
/// keep taa from blending red history into the blue shot.
fn cut_scene() -> (tempfile::TempDir, std::path::PathBuf) {
    let mut b = GltfBuilder::default();
    let extra = vec![
        json!({"mesh": 1, "name": "B", "translation": [20.0, 0.0, 0.0]}),
        json!({"camera": 0, "name": "shot camera", "translation": [0.4, 0.4, 2.5]}),
    ];
    let positions = [0.4, 0.4, 2.5, 0.3, 0.4, 2.5, 20.3, 0.4, 2.5];
    let mut doc = node_scene(
        &mut b,
        json!({}),
        None,
        extra,
        &[1, 2],
        &[vec![ChannelSpec {
            node: 2,
            path: "translation",
            interpolation: "STEP",
            times: &[0.0, 0.5, 1.0],
            values: &positions,
        }]],
    );
    let colour = |c: [f32; 4]| json!({"pbrMetallicRoughness": {"baseColorFactor": c, "metallicFactor": 0.0}});
    doc["materials"] = json!([colour([1.0, 0.1, 0.1, 1.0]), colour([0.1, 0.2, 1.0, 1.0])]);
    let mut blue = doc["meshes"][0].clone();
    doc["meshes"][0]["primitives"][0]["material"] = json!(0);
    blue["primitives"][0]["material"] = json!(1);
    doc["meshes"].as_array_mut().unwrap().push(blue);
    doc["cameras"] = json!([{
        "type": "perspective",
        "perspective": {"yfov": 0.9, "znear": 0.1, "zfar": 100.0, "aspectRatio": 1.5}
    }]);
    doc["extensions"] = json!({"KHR_lights_punctual": {"lights": [
        {"type": "directional", "intensity": 3.0}
    ]}});
    doc["extensionsUsed"] = json!(["KHR_lights_punctual"]);
    doc["nodes"][2]["children"] = json!([3]);
    doc["nodes"].as_array_mut().unwrap().push(json!({
        "name": "sun", "extensions": {"KHR_lights_punctual": {"light": 0}}
    }));
    let doc = b.finish(doc);
    write(&doc, "cut.gltf")
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn taa_drops_its_history_at_a_camera_cut() {
    if common::engine().is_none() {
        return;
    }
    let (dir, gltf) = cut_scene();
    let d = dir.path().to_str().unwrap();
    let base = [
        "taa",
        "--scene",
        gltf.to_str().unwrap(),
        "--environment",
        "none",
        "--size",
        "96x64",
        "--fps",
        "30",
    ];
    let run = |extra: &[&str]| {
        let args = [&base[..], extra].concat();
        let o = fxrun(&args);
        assert_eq!(code(&o), 0, "fxrun {}: {}", args.join(" "), stderr(&o));
    };
    run(&["--frames", "25..31", "-o", &format!("{d}/seq/%04d.png")]);
    run(&[
        "--frames",
        "30..30",
        "--warmup",
        "0",
        "-o",
        &format!("{d}/cut/%04d.png"),
    ]);
    run(&[
        "--frames",
        "29..29",
        "--warmup",
        "0",
        "-o",
        &format!("{d}/before/%04d.png"),
    ]);
    let frame = |sub: &str, n: u32| read(Path::new(&format!("{d}/{sub}/{n:04}.png")));
    // (compared as files: equal or not, without printing their bytes)
    assert!(
        frame("seq", 29) != frame("seq", 30),
        "the camera cuts to another view at frame 30"
    );
    assert!(
        frame("seq", 29) != frame("before", 29),
        "inside a shot taa's history changes its output"
    );
    assert!(
        frame("seq", 30) == frame("cut", 30),
        "the frame after the cut carries history of the previous shot"
    );
}
