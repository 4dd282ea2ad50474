//! Checking a plan by simulation, and showing it (`--plan`, `--plan --json`).

use super::*;

impl Plan {
    /// Simulate the steps and check the invariants: every value is allocated before
    /// it is written, read only while alive, never written into a slot that holds
    /// another live value, and freed exactly once. Returns the bytes actually held at
    /// the peak (which must equal `peak_bytes`).
    pub fn validate(&self) -> Result<u64, String> {
        let mut sim = Simulation {
            plan: self,
            slot_holder: vec![None; self.slots.len()],
            slot_exists: vec![false; self.slots.len()],
            alive: vec![false; self.values.len()],
            done: vec![false; self.values.len()],
        };
        let mut peak = 0u64;
        for step in &self.steps {
            match *step {
                Step::Alloc {
                    value,
                    slot,
                    create,
                } => sim.alloc(value, slot, create)?,
                Step::Run { pass } => peak = peak.max(sim.run(pass)?),
                Step::Free {
                    value,
                    slot,
                    release,
                } => sim.free(value, slot, release)?,
            }
        }
        if let Some(v) = sim.alive.iter().position(|&a| a) {
            return Err(format!("value {v} never freed"));
        }
        if sim.slot_exists.iter().any(|&e| e) {
            return Err("a slot is still held at the end".into());
        }
        if peak != self.peak_bytes {
            return Err(format!(
                "simulated peak {peak} != reported {}",
                self.peak_bytes
            ));
        }
        Ok(peak)
    }

    /// Human-readable schedule, steps and byte figures.
    pub fn render(&self) -> String {
        use std::fmt::Write as _;
        let mut out = String::new();
        let _ = writeln!(
            out,
            "input {}x{} {} ({})",
            self.input.width, self.input.height, self.input.format, self.input.colorspace
        );
        let _ = writeln!(out, "passes:");
        for (i, p) in self.passes.iter().enumerate() {
            let _ = writeln!(out, "  {i:>2} {}", self.pass_line(p));
        }
        let _ = writeln!(out, "steps:");
        for s in &self.steps {
            let _ = writeln!(out, "  {}", self.step_line(s));
        }
        self.render_figures(&mut out);
        out
    }

    /// A pass in [`Plan::render`]: path, size, format, colour space, what it
    /// reads and writes.
    fn pass_line(&self, p: &PlannedPass) -> String {
        let ins: Vec<String> = p
            .inputs
            .iter()
            .map(|i| format!("{}={}", i.name, self.resource_name(&i.resource)))
            .collect();
        format!(
            "{:<28} {:>5}x{:<5} {:<10} {:<6} <- {}  -> {}",
            p.path,
            p.desc.width,
            p.desc.height,
            p.desc.format.name(),
            p.colorspace.name(),
            ins.join(" "),
            self.resource_name(&p.output)
        )
    }

    /// A step in [`Plan::render`].
    fn step_line(&self, s: &Step) -> String {
        match s {
            Step::Alloc {
                value,
                slot,
                create,
            } => {
                let d = self.values[*value].desc;
                let mips = if d.mips > 1 {
                    format!(" {} mip levels", d.mips)
                } else {
                    String::new()
                };
                format!(
                    "alloc  v{value} -> t{slot} {}x{} {}{mips}{}",
                    d.width,
                    d.height,
                    d.format,
                    if *create { " (new)" } else { " (reused)" }
                )
            }
            Step::Run { pass } => format!("run    {}", self.passes[*pass].path),
            Step::Free {
                value,
                slot,
                release,
            } => format!(
                "free   v{value} (t{slot}{})",
                if *release {
                    " released"
                } else {
                    " kept for reuse"
                }
            ),
        }
    }

    /// The byte figures, frames kept and jitter of [`Plan::render`].
    fn render_figures(&self, out: &mut String) {
        use std::fmt::Write as _;
        for (what, bytes) in [
            ("naive bytes:      ", self.naive_bytes),
            ("peak bytes:       ", self.peak_bytes),
            ("lower bound bytes:", self.lower_bound_bytes),
            ("persistent bytes: ", self.persistent_bytes),
        ] {
            let mib = bytes as f64 / (1024.0 * 1024.0);
            let _ = writeln!(out, "{what} {bytes:>12} ({mib:.2} MiB)");
        }
        if self.latency > 0 || self.history > 0 {
            let _ = writeln!(
                out,
                "frames: {} before, {} after (latency {})",
                self.history, self.latency, self.latency
            );
        }
        if let Some(j) = self.jitter {
            let _ = writeln!(
                out,
                "jitter: {j} (input frames rendered with sub-pixel offsets, period {})",
                j.period()
            );
        }
    }

    pub fn resource_name(&self, r: &Resource) -> String {
        match r {
            Resource::Input { frame: 0 } => "IN".into(),
            Resource::Input { frame } => format!("IN[{frame:+}]"),
            Resource::Aux(n) => format!("AUX.{n}"),
            Resource::Value(v) => format!("v{v}"),
            Resource::Persistent { ring, back } => format!("{}[-{back}]", self.rings[*ring].pass),
            Resource::Output => "OUT".into(),
        }
    }

    /// The plan as a JSON object (schedule, steps and byte figures).
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "input": { "width": self.input.width, "height": self.input.height, "format": self.input.format.name() },
            "passes": self.passes.iter().map(|p| p.path.clone()).collect::<Vec<_>>(),
            "pass_details": self.passes.iter().map(|p| serde_json::json!({
                "path": p.path, "width": p.desc.width, "height": p.desc.height,
                "format": p.desc.format.name(), "colorspace": p.colorspace.name(),
                "inputs": p.inputs.iter().map(|i| serde_json::json!({"name": i.name, "resource": self.resource_name(&i.resource)})).collect::<Vec<_>>(),
                "output": self.resource_name(&p.output),
            })).collect::<Vec<_>>(),
            "steps": self.steps,
            "slots": self.slots,
            "naive_bytes": self.naive_bytes,
            "peak_bytes": self.peak_bytes,
            "lower_bound_bytes": self.lower_bound_bytes,
            "persistent_bytes": self.persistent_bytes,
            "latency": self.latency,
            "history": self.history,
            "jitter": self.jitter.map(|j| j.name()),
        })
    }
}

/// The state of [`Plan::validate`]'s simulation: who holds each slot, which
/// slots exist, which values are alive or done.
struct Simulation<'p> {
    plan: &'p Plan,
    slot_holder: Vec<Option<usize>>,
    slot_exists: Vec<bool>,
    alive: Vec<bool>,
    done: Vec<bool>,
}

impl Simulation<'_> {
    /// `Alloc`: a value not allocated before, into a free slot of its
    /// descriptor, created exactly when it does not exist.
    fn alloc(&mut self, value: usize, slot: usize, create: bool) -> Result<(), String> {
        if self.done[value] || self.alive[value] {
            return Err(format!("value {value} allocated twice"));
        }
        if let Some(other) = self.slot_holder[slot] {
            return Err(format!(
                "value {value} allocated in slot {slot} still holding live value {other}"
            ));
        }
        if create == self.slot_exists[slot] {
            return Err(format!(
                "slot {slot}: create={create} but exists={}",
                self.slot_exists[slot]
            ));
        }
        if self.plan.slots[slot] != self.plan.values[value].desc {
            return Err(format!(
                "value {value} does not match slot {slot}'s descriptor"
            ));
        }
        self.slot_exists[slot] = true;
        self.slot_holder[slot] = Some(value);
        self.alive[value] = true;
        Ok(())
    }

    /// `Run`: the pass reads alive values and writes one that owns its slot;
    /// returns the bytes of the slots held meanwhile.
    fn run(&self, pass: usize) -> Result<u64, String> {
        let plan = self.plan;
        let p = &plan.passes[pass];
        for inp in &p.inputs {
            if let Resource::Value(v) = inp.resource {
                if !self.alive[v] {
                    return Err(format!(
                        "pass {} reads value {v} which is not alive",
                        p.path
                    ));
                }
            }
        }
        if let Resource::Value(v) = p.output {
            if !self.alive[v] || self.slot_holder[plan.values[v].slot] != Some(v) {
                return Err(format!(
                    "pass {} writes value {v} that does not own its slot",
                    p.path
                ));
            }
            if p.inputs.iter().any(|i| i.resource == p.output) {
                return Err(format!("pass {} reads its own output", p.path));
            }
        }
        Ok((0..plan.slots.len())
            .filter(|&s| self.slot_exists[s])
            .map(|s| plan.slots[s].bytes())
            .sum())
    }

    /// `Free`: an alive value in its slot; the slot is destroyed if `release`.
    fn free(&mut self, value: usize, slot: usize, release: bool) -> Result<(), String> {
        if !self.alive[value] || self.slot_holder[slot] != Some(value) {
            return Err(format!("value {value} freed but not alive in slot {slot}"));
        }
        self.alive[value] = false;
        self.done[value] = true;
        self.slot_holder[slot] = None;
        if release {
            self.slot_exists[slot] = false;
        }
        Ok(())
    }
}
