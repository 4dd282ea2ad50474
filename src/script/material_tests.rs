use super::*;
use crate::script::{parse_module, Diagnostics, Severity, SourceMap};

/// Parse and check `text` as `bricks.fx`; diagnostics sorted by position.
fn check(text: &str) -> (Module, Diagnostics, SourceMap) {
    let mut sources = SourceMap::new();
    let id = sources.add("bricks.fx", text);
    let mut diags = Diagnostics::default();
    let module = parse_module(&sources, id, &mut diags);
    diags.sort();
    (module, diags, sources)
}

/// Every diagnostic rendered, in source order.
fn rendered(text: &str) -> Vec<String> {
    let (_, diags, sources) = check(text);
    diags.list.iter().map(|d| d.render(&sources)).collect()
}

fn span_text(text: &str, span: Span) -> &str {
    &text[span.start as usize..span.end as usize]
}

const BRICK: &str = r#"// A material next to nothing else.
MATERIAL.brick = {
    DESCRIPTION = "red brick wall"
    SURFACE = SHADER.standard {
        base_color_map = "textures/brick.png"
        normal_map = "textures/brick_n.png"
        roughness = 0.8
        base_color = (0.8, 0.3, 0.2, 1)
        DOUBLE_IT = true
        flip = false
        offset = -2.5e-1
    }
    LIGHTING = SHADER.phong { SPECULAR_POWER = 32 }
    ALPHA = mask
    ALPHA_CUTOFF = 0.5
    DOUBLE_SIDED = true
}
"#;

#[test]
fn full_material_builds_the_expected_ast() {
    let (m, diags, sources) = check(BRICK);
    assert!(diags.is_empty(), "{}", diags.render(&sources));
    assert!(m.effects.is_empty());
    assert_eq!(m.materials.len(), 1);
    let b = m.material("brick").expect("brick");
    assert_eq!(b.name.node, "brick");
    assert_eq!(span_text(BRICK, b.name.span), "brick");
    assert!(span_text(BRICK, b.span).starts_with("MATERIAL.brick = {"));
    assert!(span_text(BRICK, b.span).ends_with('}'));
    assert_eq!(b.description.as_deref(), Some("red brick wall"));

    let s = &b.surface;
    assert_eq!(s.shader.node, "standard");
    assert_eq!(span_text(BRICK, s.shader.span), "standard");
    assert!(span_text(BRICK, s.span).starts_with("SHADER.standard {"));
    let settings: Vec<(&str, &MaterialValue)> = s
        .settings
        .iter()
        .map(|x| (x.name.node.as_str(), &x.value.node))
        .collect();
    use MaterialValue::*;
    assert_eq!(
        settings,
        vec![
            ("base_color_map", &Text("textures/brick.png".into())),
            ("normal_map", &Text("textures/brick_n.png".into())),
            ("roughness", &Numbers(vec![0.8])),
            ("base_color", &Numbers(vec![0.8, 0.3, 0.2, 1.0])),
            ("DOUBLE_IT", &Numbers(vec![1.0])),
            ("flip", &Numbers(vec![0.0])),
            ("offset", &Numbers(vec![-0.25])),
        ]
    );
    let rough = s.setting("roughness").unwrap();
    assert_eq!(span_text(BRICK, rough.name.span), "roughness");
    assert_eq!(span_text(BRICK, rough.value.span), "0.8");
    assert_eq!(
        span_text(BRICK, s.setting("base_color").unwrap().value.span),
        "(0.8, 0.3, 0.2, 1)"
    );

    let l = &b.lighting;
    assert_eq!(l.shader.node, "phong");
    assert_eq!(
        span_text(BRICK, l.span),
        "SHADER.phong { SPECULAR_POWER = 32 }"
    );
    assert_eq!(l.settings.len(), 1);
    assert_eq!(l.settings[0].name.node, "SPECULAR_POWER");
    assert_eq!(l.settings[0].value.node, Numbers(vec![32.0]));

    let alpha = b.alpha.as_ref().unwrap();
    assert_eq!(alpha.node, AlphaSpec::Mask);
    assert_eq!(span_text(BRICK, alpha.span), "mask");
    let cutoff = b.alpha_cutoff.as_ref().unwrap();
    assert_eq!(cutoff.node, 0.5);
    assert_eq!(span_text(BRICK, cutoff.span), "0.5");
    let ds = b.double_sided.as_ref().unwrap();
    assert!(ds.node);
    assert_eq!(span_text(BRICK, ds.span), "true");
}

#[test]
fn minimal_material_and_shader_without_block() {
    let text = "MATERIAL.plain = {\n    SURFACE = SHADER.flat\n    LIGHTING = SHADER.lambert\n}\n";
    let (m, diags, sources) = check(text);
    assert!(diags.is_empty(), "{}", diags.render(&sources));
    let p = &m.materials[0];
    assert_eq!(p.description, None);
    assert_eq!(p.surface.shader.node, "flat");
    assert!(p.surface.settings.is_empty());
    assert_eq!(span_text(text, p.surface.span), "SHADER.flat");
    assert_eq!(p.lighting.shader.node, "lambert");
    assert!(p.lighting.settings.is_empty());
    assert_eq!(
        (
            p.alpha.clone(),
            p.alpha_cutoff.clone(),
            p.double_sided.clone()
        ),
        (None, None, None)
    );
}

#[test]
fn tuples_up_to_a_matrix() {
    let sixteen = (0..16)
        .map(|i| i.to_string())
        .collect::<Vec<_>>()
        .join(", ");
    let text = format!(
        "MATERIAL.m = {{\n    SURFACE = SHADER.s {{ xform = ({sixteen}) one = (3) }}\n    LIGHTING = SHADER.l\n}}\n"
    );
    let (m, diags, sources) = check(&text);
    assert!(diags.is_empty(), "{}", diags.render(&sources));
    let s = &m.materials[0].surface;
    assert_eq!(
        s.setting("xform").unwrap().value.node,
        MaterialValue::Numbers((0..16).map(f64::from).collect())
    );
    assert_eq!(
        s.setting("one").unwrap().value.node,
        MaterialValue::Numbers(vec![3.0])
    );

    let seventeen = format!("{sixteen}, 16");
    let text = format!(
        "MATERIAL.m = {{\n    SURFACE = SHADER.s {{ xform = ({seventeen}) }}\n    LIGHTING = SHADER.l\n}}\n"
    );
    let (m, diags, sources) = check(&text);
    assert_eq!(diags.error_count(), 1, "{}", diags.render(&sources));
    assert!(diags.list[0]
        .message
        .contains("a tuple of 17 numbers in `xform`: at most 16"));
    // The material still comes out, without the bad setting.
    assert!(m.materials[0].surface.settings.is_empty());
}

#[test]
fn materials_effects_and_includes_in_one_file() {
    let text = r#"INCLUDE "common.fx"
EFFECT.copy = {
    PASS = { c = SHADER.copy { img = IN } }
    OUT = c
}
MATERIAL.brick = {
    SURFACE = SHADER.standard { roughness = 0.8 }
    LIGHTING = SHADER.lambert
}
EFFECT.blur = {
    PASS = { b = SHADER.blur { img = IN } }
    OUT = b
}
MATERIAL.glass = {
    SURFACE = SHADER.standard { base_color = (1, 1, 1, 0.2) }
    LIGHTING = SHADER.phong { SPECULAR_POWER = 64 }
    ALPHA = blend
}
"#;
    let (m, diags, sources) = check(text);
    assert!(diags.is_empty(), "{}", diags.render(&sources));
    assert_eq!(m.includes.len(), 1);
    assert_eq!(m.includes[0].node, "common.fx");
    let effects: Vec<&str> = m.effects.iter().map(|e| e.name.node.as_str()).collect();
    assert_eq!(effects, ["copy", "blur"]);
    let materials: Vec<&str> = m.materials.iter().map(|e| e.name.node.as_str()).collect();
    assert_eq!(materials, ["brick", "glass"]);
    assert_eq!(
        m.material("glass").unwrap().alpha.as_ref().unwrap().node,
        AlphaSpec::Blend
    );
    assert_eq!(m.effects[0].passes[0].name.node, "c");
}

#[test]
fn bad_material_and_bad_effect_are_both_checked() {
    let text = r#"EFFECT.broken = {
    PASS = { c = SHADER.copy { img = PASS.nope } }
    OUT = c
}
MATERIAL.broken = {
    SURFACE = SHADER.standard { img = IN }
    LIGHTING = SHADER.lambert
}
EFFECT.fine = {
    PASS = { c = SHADER.copy { img = IN } }
    OUT = c
}
MATERIAL.fine = {
    SURFACE = SHADER.standard
    LIGHTING = SHADER.lambert
}
"#;
    let (m, diags, sources) = check(text);
    let messages: Vec<&str> = diags.list.iter().map(|d| d.message.as_str()).collect();
    assert_eq!(
        messages,
        [
            "unknown pass `nope`",
            "`img` expects a number, a tuple of numbers, `true`/`false` or a texture path `\"file.png\"`, found `IN`",
        ],
        "{}",
        diags.render(&sources)
    );
    assert!(m.effects.iter().any(|e| e.name.node == "fine"));
    assert!(m.material("fine").is_some());
    // The broken material has its SURFACE and LIGHTING, only the bad setting is gone.
    assert!(m.material("broken").unwrap().surface.settings.is_empty());
}

#[test]
fn snapshot_surface_is_an_effect() {
    let text =
        "MATERIAL.brick = {\n    SURFACE = EFFECT.glow { }\n    LIGHTING = SHADER.lambert\n}\n";
    assert_eq!(
        rendered(text),
        [
            r#"bricks.fx:2:15: error: a material's `SURFACE` is a shader, not an effect: found `EFFECT.glow`
  |
2 |     SURFACE = EFFECT.glow { }
  |               ^^^^^^^^^^^ expected `SHADER.<name>`
  = note: effects are filter graphs over images; a material's SURFACE and LIGHTING are single WGSL shaders
"#
        ]
    );
    // Reported once: a wrong SURFACE is not also a missing one.
    let (m, _, _) = check(text);
    assert!(m.materials.is_empty());
}

#[test]
fn snapshot_missing_lighting() {
    let text = "MATERIAL.brick = {\n    SURFACE = SHADER.standard\n}\n";
    assert_eq!(
        rendered(text),
        [r#"bricks.fx:1:10: error: material `brick` has no `LIGHTING`
  |
1 | MATERIAL.brick = {
  |          ^^^^^ this material never says which shader lights it
  = note: add e.g. `LIGHTING = SHADER.lambert`
"#]
    );
}

#[test]
fn snapshot_missing_surface_and_lighting() {
    let text = "MATERIAL.empty = { }\n";
    assert_eq!(
        rendered(text),
        [
            r#"bricks.fx:1:10: error: material `empty` has no `SURFACE`
  |
1 | MATERIAL.empty = { }
  |          ^^^^^ this material never says which shader draws its surface
  = note: add e.g. `SURFACE = SHADER.standard { base_color = (1, 1, 1, 1) }`
"#,
            r#"bricks.fx:1:10: error: material `empty` has no `LIGHTING`
  |
1 | MATERIAL.empty = { }
  |          ^^^^^ this material never says which shader lights it
  = note: add e.g. `LIGHTING = SHADER.lambert`
"#
        ]
    );
}

#[test]
fn snapshot_unknown_key_with_suggestion() {
    let text = "MATERIAL.brick = {\n    SURFACE = SHADER.standard\n    LIGHTING = SHADER.lambert\n    DOUBLESIDED = true\n    SHININESS = 3\n}\n";
    assert_eq!(
        rendered(text),
        [
            r#"bricks.fx:4:5: error: unknown material attribute `DOUBLESIDED`
  |
4 |     DOUBLESIDED = true
  |     ^^^^^^^^^^^ not a material attribute
  = note: did you mean `DOUBLE_SIDED`?
"#,
            r#"bricks.fx:5:5: error: unknown material attribute `SHININESS`
  |
5 |     SHININESS = 3
  |     ^^^^^^^^^ not a material attribute
  = note: a material may contain DESCRIPTION, SURFACE, LIGHTING, ALPHA, ALPHA_CUTOFF, DOUBLE_SIDED
"#
        ]
    );
}

#[test]
fn snapshot_setting_values() {
    let text = r#"MATERIAL.brick = {
    SURFACE = SHADER.standard {
        albedo = PASS.blur
        tex = brick_png
        nested = { a = 1 }
        color = (1, red, 0)
        path = ""
        tint.r = 1
    }
    LIGHTING = SHADER.lambert
}
"#;
    assert_eq!(
        rendered(text),
        [
            r#"bricks.fx:3:18: error: `albedo` expects a number, a tuple of numbers, `true`/`false` or a texture path `"file.png"`, found `PASS.blur`
  |
3 |         albedo = PASS.blur
  |                  ^^^^^^^^^ not a material setting value
  = note: a material reads no images or parameters of an effect; textures are file paths in quotes
"#,
            r#"bricks.fx:4:15: error: `tex` expects a number, a tuple of numbers, `true`/`false` or a texture path `"file.png"`, found `brick_png`
  |
4 |         tex = brick_png
  |               ^^^^^^^^^ not a material setting value
  = note: a texture path is written in quotes: `"brick_png"`
"#,
            r#"bricks.fx:5:18: error: `nested` expects a number, a tuple of numbers, `true`/`false` or a texture path `"file.png"`, found a block `{ ... }`
  |
5 |         nested = { a = 1 }
  |                  ^^^^^^^^^ expected a number, a tuple of numbers, `true`/`false` or a texture path `"file.png"`
"#,
            r#"bricks.fx:6:21: error: a tuple in `color` holds numbers only, found `red`
  |
6 |         color = (1, red, 0)
  |                     ^^^ expected a number
"#,
            r#"bricks.fx:7:16: error: `path` is an empty texture path
  |
7 |         path = ""
  |                ^^ expected a file path such as "textures/brick.png"
"#,
            r#"bricks.fx:8:9: error: a shader setting name is a single word, found `tint.r`
  |
8 |         tint.r = 1
  |         ^^^^^^ expected `name = value`
"#,
        ]
    );
}

#[test]
fn snapshot_alpha_cutoff_double_sided() {
    let text = r#"MATERIAL.brick = {
    SURFACE = SHADER.standard
    LIGHTING = SHADER.lambert
    ALPHA = masked
    ALPHA_CUTOFF = 1.5
    DOUBLE_SIDED = 1
}
"#;
    assert_eq!(
        rendered(text),
        [
            r#"bricks.fx:4:13: error: unknown alpha mode `masked`
  |
4 |     ALPHA = masked
  |             ^^^^^^ expected `opaque`, `mask` or `blend`
  = note: did you mean `mask`?
"#,
            r#"bricks.fx:5:20: error: `ALPHA_CUTOFF` must be between 0 and 1, found 1.5
  |
5 |     ALPHA_CUTOFF = 1.5
  |                    ^^^ out of range [0, 1]
"#,
            r#"bricks.fx:6:20: error: `DOUBLE_SIDED` expects `true` or `false`, found a number
  |
6 |     DOUBLE_SIDED = 1
  |                    ^ expected `true` or `false`
"#,
        ]
    );
}

#[test]
fn snapshot_wrong_value_kinds_for_attributes() {
    let text = r#"MATERIAL.brick = {
    DESCRIPTION = brick
    SURFACE = (1, 2)
    LIGHTING = SHADER.lambert[-1]
    ALPHA = (1, 0)
    ALPHA_CUTOFF = mask
    DOUBLE_SIDED = yes
}
"#;
    assert_eq!(
        rendered(text),
        [
            r#"bricks.fx:2:19: error: `DESCRIPTION` expects a string, found a name
  |
2 |     DESCRIPTION = brick
  |                   ^^^^^ expected a string
"#,
            r#"bricks.fx:3:15: error: `SURFACE` expects a shader `SHADER.name { ... }`, found a tuple
  |
3 |     SURFACE = (1, 2)
  |               ^^^^^^ expected a shader `SHADER.name { ... }`
"#,
            r#"bricks.fx:4:31: error: a material shader has no earlier or later frames
  |
4 |     LIGHTING = SHADER.lambert[-1]
  |                               ^^ remove the frame offset
"#,
            r#"bricks.fx:5:13: error: `ALPHA` expects `opaque`, `mask` or `blend`, found a tuple
  |
5 |     ALPHA = (1, 0)
  |             ^^^^^^ expected `opaque`, `mask` or `blend`
"#,
            r#"bricks.fx:6:20: error: `ALPHA_CUTOFF` expects a number between 0 and 1, found a name
  |
6 |     ALPHA_CUTOFF = mask
  |                    ^^^^ expected a number between 0 and 1
"#,
            r#"bricks.fx:7:20: error: `DOUBLE_SIDED` expects `true` or `false`, found `yes`
  |
7 |     DOUBLE_SIDED = yes
  |                    ^^^ expected `true` or `false`
"#,
        ]
    );
}

#[test]
fn snapshot_duplicates() {
    let text = r#"MATERIAL.brick = {
    SURFACE = SHADER.standard { roughness = 0.8  roughness = 0.9 }
    LIGHTING = SHADER.lambert
    LIGHTING = SHADER.phong
}
MATERIAL.brick = {
    SURFACE = SHADER.other
    LIGHTING = SHADER.lambert
}
"#;
    assert_eq!(
        rendered(text),
        [
            r#"bricks.fx:2:50: error: `roughness` is set twice in the `SURFACE` of material `brick`
  |
2 |     SURFACE = SHADER.standard { roughness = 0.8  roughness = 0.9 }
  |                                                  ^^^^^^^^^ set again here
 --> bricks.fx:2:33
  |
2 |     SURFACE = SHADER.standard { roughness = 0.8  roughness = 0.9 }
  |                                 --------- first set here
"#,
            r#"bricks.fx:4:5: error: `LIGHTING` is set twice in material `brick`
  |
4 |     LIGHTING = SHADER.phong
  |     ^^^^^^^^ set again here
 --> bricks.fx:3:5
  |
3 |     LIGHTING = SHADER.lambert
  |     -------- first set here
"#,
            r#"bricks.fx:6:10: error: material `brick` is defined twice
  |
6 | MATERIAL.brick = {
  |          ^^^^^ defined again here
 --> bricks.fx:1:10
  |
1 | MATERIAL.brick = {
  |          ----- first defined here
"#,
        ]
    );
    // The first definition is kept.
    let (m, _, _) = check(text);
    assert_eq!(m.materials.len(), 1);
    assert_eq!(m.materials[0].surface.shader.node, "standard");
    assert_eq!(m.materials[0].lighting.shader.node, "lambert");
}

#[test]
fn alpha_cutoff_without_mask_is_a_warning() {
    let text = "MATERIAL.brick = {\n    SURFACE = SHADER.standard\n    LIGHTING = SHADER.lambert\n    ALPHA = opaque\n    ALPHA_CUTOFF = 0.5\n}\n";
    let (m, diags, _) = check(text);
    assert_eq!(diags.list.len(), 1);
    assert_eq!(diags.list[0].severity, Severity::Warning);
    assert!(!diags.has_errors());
    assert_eq!(m.materials[0].alpha_cutoff.as_ref().unwrap().node, 0.5);
    assert_eq!(
        rendered(text),
        [
            r#"bricks.fx:5:20: warning: `ALPHA_CUTOFF` has no effect unless `ALPHA = mask`
  |
5 |     ALPHA_CUTOFF = 0.5
  |                    ^^^ ignored
 --> bricks.fx:4:13
  |
4 |     ALPHA = opaque
  |             ------ the alpha mode is `opaque`
"#
        ]
    );
}

#[test]
fn three_mistakes_in_one_run() {
    let text = r#"MATERIAL.brick = {
    SURFACE = SHADER.standard { roughness = PASS.x }
    ALPHA = see_through
    DOUBLE_SIDED = true
}
"#;
    let (m, diags, sources) = check(text);
    let out = diags.render(&sources);
    assert_eq!(diags.error_count(), 3, "{out}");
    let locations: Vec<String> = diags
        .list
        .iter()
        .map(|d| sources.location(d.primary_span().unwrap()))
        .collect();
    assert_eq!(
        locations,
        ["bricks.fx:1:10", "bricks.fx:2:45", "bricks.fx:3:13"]
    );
    assert!(out.contains("error: material `brick` has no `LIGHTING`"));
    assert!(out.contains("found `PASS.x`"));
    assert!(out.contains("error: unknown alpha mode `see_through`"));
    assert!(out.ends_with("3 errors, 0 warnings\n"), "{out}");
    assert!(m.materials.is_empty());
}

#[test]
fn top_level_shapes() {
    let text = r#"MATERIAL = { SURFACE = SHADER.s  LIGHTING = SHADER.l }
MATERIAL.a.b = { SURFACE = SHADER.s  LIGHTING = SHADER.l }
MATERIAL.c = SHADER.s
MATERAIL.d = { SURFACE = SHADER.s  LIGHTING = SHADER.l }
"#;
    assert_eq!(
        rendered(text),
        [
            r#"bricks.fx:1:1: error: a material is defined as `MATERIAL.name = { ... }`, found `MATERIAL`
  |
1 | MATERIAL = { SURFACE = SHADER.s  LIGHTING = SHADER.l }
  | ^^^^^^^^ expected `MATERIAL.name`
"#,
            r#"bricks.fx:2:1: error: a material is defined as `MATERIAL.name = { ... }`, found `MATERIAL.a.b`
  |
2 | MATERIAL.a.b = { SURFACE = SHADER.s  LIGHTING = SHADER.l }
  | ^^^^^^^^^^^^ expected `MATERIAL.name`
"#,
            r#"bricks.fx:3:14: error: a material is defined with a block, found a name
  |
3 | MATERIAL.c = SHADER.s
  |              ^^^^^^^^ expected `{ SURFACE = SHADER.x { ... } LIGHTING = SHADER.y }`
"#,
            r#"bricks.fx:4:1: error: unknown top-level statement `MATERAIL.d`
  |
4 | MATERAIL.d = { SURFACE = SHADER.s  LIGHTING = SHADER.l }
  | ^^^^^^^^^^ expected `EFFECT.name = { ... }` or `INCLUDE "file.fx"`
  = note: did you mean `MATERIAL.d`?
"#,
        ]
    );
}

#[test]
fn syntax_error_resumes_at_the_next_material() {
    let text = r#"MATERIAL.broken = {
    SURFACE = SHADER.standard { roughness 0.8 }
    LIGHTING = SHADER.lambert
}
MATERIAL.good = {
    SURFACE = SHADER.standard
    LIGHTING = SHADER.lambert
}
EFFECT.e = {
    PASS = { c = SHADER.copy { img = IN } }
    OUT = c
}
"#;
    let (m, diags, sources) = check(text);
    assert_eq!(diags.error_count(), 1, "{}", diags.render(&sources));
    assert!(diags.list[0].message.starts_with("syntax error"));
    assert_eq!(
        sources.location(diags.list[0].primary_span().unwrap()),
        "bricks.fx:2:43"
    );
    assert!(m.material("good").is_some());
    assert_eq!(m.effects.len(), 1);
}
