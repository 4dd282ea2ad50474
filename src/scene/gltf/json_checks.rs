//! Checks of the raw glTF / GLB bytes made before the `gltf` crate parses them:
//! referenced files must be regular files of bounded size, `extensions` members
//! must be objects (the JSON schema), and the references the crate would panic on
//! must exist.

use std::path::Path;

/// Largest glTF, GLB or referenced buffer/image file read (2 GiB).
pub const MAX_GLTF_FILE_BYTES: u64 = 2 << 30;

/// The files the glTF's buffers and images name (`uri`s that are not `data:` URIs) must be
/// regular files of at most [`MAX_GLTF_FILE_BYTES`]: checked before the glTF importer
/// reads them (`"uri": "/dev/zero"` would never end). A missing file is left to the
/// importer's message.
pub(super) fn check_uris(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let json = json_bytes(bytes)?;
    let value: serde_json::Value =
        serde_json::from_slice(json).map_err(|e| format!("invalid JSON: {e}"))?;
    let base = path.parent().unwrap_or(Path::new("."));
    for key in ["buffers", "images"] {
        let Some(list) = value.get(key).and_then(|v| v.as_array()) else {
            continue;
        };
        for (i, item) in list.iter().enumerate() {
            let Some(uri) = item.get("uri").and_then(|u| u.as_str()) else {
                continue;
            };
            if uri.starts_with("data:") {
                continue;
            }
            let file = uri.strip_prefix("file://").unwrap_or(uri);
            let target = base.join(file);
            let Ok(meta) = std::fs::metadata(&target) else {
                continue;
            };
            if !meta.is_file() {
                return Err(format!(
                    "{key}[{i}].uri `{uri}` is not a regular file (a device, a pipe or a folder cannot be read)"
                ));
            }
            if meta.len() > MAX_GLTF_FILE_BYTES {
                return Err(format!(
                    "{key}[{i}].uri `{uri}` is too large ({} bytes; the limit is {MAX_GLTF_FILE_BYTES} bytes)",
                    meta.len()
                ));
            }
        }
    }
    Ok(())
}

/// The JSON chunk of a `.glb`, or the whole file.
fn json_bytes(bytes: &[u8]) -> Result<&[u8], String> {
    if bytes.len() >= 4 && &bytes[..4] == b"glTF" {
        if bytes.len() < 20 {
            return Err("truncated GLB header".into());
        }
        let len = u32::from_le_bytes([bytes[12], bytes[13], bytes[14], bytes[15]]) as usize;
        let kind = &bytes[16..20];
        if kind != b"JSON" {
            return Err("the first GLB chunk is not JSON".into());
        }
        bytes
            .get(20..20usize.saturating_add(len))
            .ok_or_else(|| "truncated GLB JSON chunk".to_string())
    } else {
        Ok(bytes)
    }
}

/// Schema checks the `gltf` crate does not make: every `extensions` member is an
/// object whose values are objects (glTF `extension.schema.json`).
pub(super) fn check_json_schema(bytes: &[u8]) -> Result<(), String> {
    let json = json_bytes(bytes)?;
    let value: serde_json::Value =
        serde_json::from_slice(json).map_err(|e| format!("invalid JSON: {e}"))?;
    fn walk(v: &serde_json::Value, path: &mut Vec<String>, depth: usize) -> Result<(), String> {
        if depth > 256 {
            return Err("JSON nested too deeply".into());
        }
        match v {
            serde_json::Value::Object(map) => {
                for (k, child) in map {
                    if k == "extras" {
                        continue;
                    }
                    if k == "extensions" {
                        let serde_json::Value::Object(exts) = child else {
                            return Err(format!("{}/extensions must be an object", path.join("/")));
                        };
                        for (name, ext) in exts {
                            if !ext.is_object() {
                                return Err(format!(
                                    "{}/extensions/{name} must be an object, found {ext}",
                                    path.join("/")
                                ));
                            }
                        }
                    }
                    path.push(k.clone());
                    walk(child, path, depth + 1)?;
                    path.pop();
                }
            }
            serde_json::Value::Array(items) => {
                for (i, child) in items.iter().enumerate() {
                    path.push(i.to_string());
                    walk(child, path, depth + 1)?;
                    path.pop();
                }
            }
            _ => {}
        }
        Ok(())
    }
    walk(&value, &mut vec![String::new()], 0)
}

/// References the `gltf` crate follows before (or without) checking them, so that a
/// damaged file would make it panic, checked first and reported as the path of the
/// JSON member at fault:
///
/// - a primitive's `POSITION` accessor: gltf-json's validation reads its `min` and
///   `max` by indexing the accessor list with it (every attribute is checked here);
/// - an image's source: `uri`, or `bufferView` with `mimeType` (glTF 2.0, 5.18:
///   "`bufferView` ... `mimeType` MUST also be defined"); the crate unwraps both.
pub(super) fn check_references(bytes: &[u8]) -> Result<(), String> {
    let value: serde_json::Value =
        serde_json::from_slice(json_bytes(bytes)?).map_err(|e| format!("invalid JSON: {e}"))?;
    let count = |key: &str| {
        value
            .get(key)
            .and_then(|v| v.as_array())
            .map_or(0, Vec::len)
    };
    let list = |v: &serde_json::Value, key: &str| {
        v.get(key)
            .and_then(|l| l.as_array())
            .cloned()
            .unwrap_or_default()
    };
    let accessors = count("accessors");
    for (m, mesh) in list(&value, "meshes").iter().enumerate() {
        for (p, prim) in list(mesh, "primitives").iter().enumerate() {
            let Some(attrs) = prim.get("attributes").and_then(|a| a.as_object()) else {
                continue;
            };
            for (name, index) in attrs {
                let Some(i) = index.as_u64() else { continue };
                if i as usize >= accessors {
                    return Err(format!(
                        "meshes[{m}].primitives[{p}].attributes.{name}: accessor {i} does not exist (the file has {accessors} accessor{})",
                        if accessors == 1 { "" } else { "s" }
                    ));
                }
            }
        }
    }
    for (i, image) in list(&value, "images").iter().enumerate() {
        let has = |k: &str| image.get(k).is_some_and(|v| !v.is_null());
        if has("bufferView") {
            if !has("mimeType") {
                return Err(format!(
                    "images[{i}]: an image in a `bufferView` needs a `mimeType`"
                ));
            }
        } else if !has("uri") {
            return Err(format!(
                "images[{i}]: neither `uri` nor `bufferView` says where the image is"
            ));
        }
    }
    Ok(())
}
