//! A wgpu error as one line for a user. wgpu's `Display` is a report over several
//! lines (`Validation Error`, `Caused by:`, the call with its label, then each cause
//! indented) with `Debug` forms inside (`ShaderStages(FRAGMENT)`, `Some(Perspective)`).
//! Here the chain of causes is walked instead and joined with `: `; the call and
//! its label are left out (the [`super::GpuError`] names what was being done), the
//! `Debug` wrappers are unwrapped, and naga's type forms in a shader's validation
//! error are written as WGSL types ([`crate::shader::wgsl_names::sanitize`]).

/// The causes of `e`, innermost last, joined with `: `.
pub fn wgpu_error_text(e: &wgpu::Error) -> String {
    let source: &(dyn std::error::Error + 'static) = match e {
        wgpu::Error::OutOfMemory { source } => source.as_ref(),
        wgpu::Error::Validation { source, .. } => source.as_ref(),
        wgpu::Error::Internal { source, .. } => source.as_ref(),
    };
    let mut parts = Vec::new();
    let mut next = Some(source);
    while let Some(err) = next {
        let text = err.to_string();
        // wgpu-core's context line (`In Device::create_render_pipeline, label = '...'`).
        if !(text.starts_with("In ") && text.contains("::")) {
            let text = crate::shader::wgsl_names::sanitize(&tidy(text.trim()));
            if !text.is_empty() && parts.last() != Some(&text) {
                parts.push(text);
            }
        }
        next = err.source();
    }
    if parts.is_empty() {
        // No cause to walk: the description's first line that is not the heading.
        let description = e.to_string();
        return description
            .lines()
            .map(str::trim)
            .find(|l| !l.is_empty() && !l.ends_with("Error") && *l != "Caused by:")
            .map_or(description.clone(), tidy);
    }
    parts.join(": ")
}

/// `Some(x)` → `x`, `ShaderStages(FRAGMENT | VERTEX)` → `fragment | vertex`, and
/// each line of a multi-line message joined with spaces.
fn tidy(text: &str) -> String {
    let mut s = text.lines().map(str::trim).collect::<Vec<_>>().join(" ");
    for (open, lower) in [("Some(", false), ("ShaderStages(", true)] {
        while let Some(i) = s.find(open) {
            let inner_start = i + open.len();
            let mut depth = 1;
            let mut end = None;
            for (k, c) in s[inner_start..].char_indices() {
                match c {
                    '(' => depth += 1,
                    ')' => {
                        depth -= 1;
                        if depth == 0 {
                            end = Some(inner_start + k);
                            break;
                        }
                    }
                    _ => {}
                }
            }
            let Some(end) = end else { break };
            let inner = &s[inner_start..end];
            let inner = if lower {
                inner.to_lowercase()
            } else {
                inner.to_string()
            };
            s.replace_range(i..=end, &inner);
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::tidy;

    #[test]
    fn debug_wrappers_are_unwrapped() {
        assert_eq!(
            tidy("Error matching ShaderStages(FRAGMENT) shader requirements"),
            "Error matching fragment shader requirements"
        );
        assert_eq!(
            tidy("Location[1] Float32x2 interpolated as Some(Perspective) with sampling Some(Center)"),
            "Location[1] Float32x2 interpolated as Perspective with sampling Center"
        );
        assert_eq!(tidy("a\n    b"), "a b");
    }
}
