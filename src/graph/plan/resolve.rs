//! Resolving sizes, formats and colour spaces of the passes for one input.

use super::*;

pub(super) struct Resolver<'g> {
    pub(super) graph: &'g Graph,
    pub(super) input: &'g InputDesc,
    pub(super) sizes: HashMap<NodeIndex, Option<(u32, u32)>>,
    pub(super) diags: Diagnostics,
}

impl Resolver<'_> {
    pub(super) fn size(&mut self, n: NodeIndex) -> Option<(u32, u32)> {
        if let Some(s) = self.sizes.get(&n) {
            return *s;
        }
        self.sizes.insert(n, None); // in progress: a size that depends on itself is None
        let s = match &self.graph.graph[n] {
            Node::Input { .. } | Node::Output => Some((self.input.width, self.input.height)),
            Node::Aux { name, .. } => Some(self.input.aux_size(name)),
            Node::Feedback { pass, .. } => self.size(*pass),
            Node::Pass(p) => match &p.size {
                SizeRule::Absolute(w, h) => Some((*w, *h)),
                SizeRule::Scale { sx, sy, of } => {
                    let size_of =
                        |r: &mut Self, m: NodeIndex| if m == n { None } else { r.size(m) };
                    let base = match (size_of(self, of.0), size_of(self, of.1)) {
                        (Some((w, _)), Some((_, h))) => Some((w, h)),
                        _ => None,
                    };
                    match base {
                        None => {
                            self.diags.push(
                                Diagnostic::error(format!(
                                    "the size of pass `{}` depends on itself",
                                    p.path
                                ))
                                .at(
                                    p.name_span,
                                    "its OUT.RELATIVE_TO input is sized from this pass",
                                ),
                            );
                            None
                        }
                        Some((w, h)) => {
                            let (fw, fh) = ((w as f64 * sx).round(), (h as f64 * sy).round());
                            if fw > MAX_SIDE as f64 || fh > MAX_SIDE as f64 {
                                self.diags.push(
                                    Diagnostic::error(format!(
                                        "pass `{}` would be {}x{} px for a {}x{} input, larger than {MAX_SIDE} px",
                                        p.path, fw, fh, self.input.width, self.input.height
                                    ))
                                    .at(p.name_span, "output too large"),
                                );
                                None
                            } else {
                                let out = ((fw as u32).max(1), (fh as u32).max(1));
                                let growth = (out.0 as f64 / self.input.width as f64)
                                    .max(out.1 as f64 / self.input.height as f64);
                                if growth > 4.0 {
                                    self.diags.push(
                                        Diagnostic::warning(format!(
                                            "pass `{}` is {:.0}x larger than the effect input ({}x{} px)",
                                            p.path, growth, out.0, out.1
                                        ))
                                        .at(p.name_span, "pathological growth"),
                                    );
                                }
                                Some(out)
                            }
                        }
                    }
                }
            },
        };
        self.sizes.insert(n, s);
        s
    }

    pub(super) fn format(&self, n: NodeIndex, depth: usize) -> Format {
        match &self.graph.graph[n] {
            Node::Input { .. } | Node::Output => self.input.format,
            Node::Aux { name, .. } => self
                .input
                .aux
                .iter()
                .find(|(a, _)| a == name)
                .map(|(_, f)| *f)
                .unwrap_or(Format::Rgba16f),
            Node::Feedback { pass, .. } => self.format(*pass, depth + 1),
            Node::Pass(p) => match &p.format {
                FormatRule::Fixed(f) => *f,
                FormatRule::SameAs(of) if depth < 64 => self.format(*of, depth + 1),
                FormatRule::SameAs(_) => Format::Rgba16f,
            },
        }
    }

    pub(super) fn colorspace(&self, n: NodeIndex) -> ColorSpace {
        match &self.graph.graph[n] {
            Node::Input { .. } | Node::Output => self.input.colorspace,
            Node::Aux { .. } => ColorSpace::Linear,
            Node::Feedback { pass, .. } => self.colorspace(*pass),
            Node::Pass(p) => p
                .colorspace
                .resolve(self.input.format, self.input.colorspace),
        }
    }

    pub(super) fn desc(&mut self, n: NodeIndex) -> Option<TextureDesc> {
        let (width, height) = self.size(n)?;
        Some(TextureDesc::new(width, height, self.format(n, 0)))
    }
}
