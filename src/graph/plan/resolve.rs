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
            Node::Input { .. } => Some((self.input.width, self.input.height)),
            Node::Aux { name, .. } => Some(self.input.aux_size(name)),
            Node::Output => Some(self.input.viewport()),
            Node::Feedback { pass, .. } => self.size(*pass),
            Node::Pass(p) => self.pass_size(n, p, &p.size),
        };
        self.sizes.insert(n, s);
        s
    }

    /// The size `rule` gives pass `n`, axis by axis; `None` (reported) when it
    /// depends on itself or is too large.
    fn pass_size(&mut self, n: NodeIndex, p: &PassNode, rule: &SizeRule) -> Option<(u32, u32)> {
        let w = self.axis_size(n, rule.x, |s| s.0);
        let h = self.axis_size(n, rule.y, |s| s.1);
        let (Some(fw), Some(fh)) = (w, h) else {
            self.diags.push(
                Diagnostic::error(format!("the size of pass `{}` depends on itself", p.path)).at(
                    p.name_span,
                    "its OUT.RELATIVE_TO input is sized from this pass",
                ),
            );
            return None;
        };
        if fw > MAX_SIDE as f64 || fh > MAX_SIDE as f64 {
            self.diags.push(
                Diagnostic::error(format!(
                    "pass `{}` would be {}x{} px for a {}x{} input, larger than {MAX_SIDE} px",
                    p.path, fw, fh, self.input.width, self.input.height
                ))
                .at(p.name_span, "output too large"),
            );
            return None;
        }
        let out = ((fw as u32).max(1), (fh as u32).max(1));
        let growth =
            (out.0 as f64 / self.input.width as f64).max(out.1 as f64 / self.input.height as f64);
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

    /// One axis of pass `n`'s size, in (rounded) pixels; `None` when it is
    /// scaled from the pass itself or from a node whose size depends on it.
    fn axis_size(
        &mut self,
        n: NodeIndex,
        axis: AxisSize,
        pick: fn((u32, u32)) -> u32,
    ) -> Option<f64> {
        match axis {
            AxisSize::Pixels(v) => Some(v as f64),
            AxisSize::Scale(_, of) if of == n => None,
            AxisSize::Scale(f, of) => self.size(of).map(|s| (pick(s) as f64 * f).round()),
        }
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
