//! Values to physical textures (slots) and the Alloc / Run / Free steps.

use super::*;

pub(super) fn resource_of(
    graph: &Graph,
    n: NodeIndex,
    produced: &HashMap<NodeIndex, Resource>,
    ring_of: &HashMap<NodeIndex, usize>,
) -> Resource {
    match &graph.graph[n] {
        Node::Input { frame } => Resource::Input { frame: *frame },
        Node::Aux { name, .. } => Resource::Aux(name.clone()),
        Node::Feedback { pass, back } => Resource::Persistent {
            ring: ring_of[pass],
            back: *back,
        },
        Node::Pass(_) => produced
            .get(&n)
            .cloned()
            .expect("producer scheduled before reader"),
        Node::Output => Resource::Output,
    }
}

/// Assign values to slots and build the steps. Returns (slots, steps, peak, lower bound).
pub(super) fn assign_slots(
    values: &mut [Value],
    n_passes: usize,
    policy: ReusePolicy,
) -> (Vec<TextureDesc>, Vec<Step>, u64, u64) {
    let live = live_bytes(values, n_passes);
    let lower = live.iter().copied().max().unwrap_or(0);
    let mut pool = SlotPool {
        slots: Vec::new(),
        held: live,
        lower,
        policy,
    };
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by_key(|&v| (values[v].producer, v));
    let mut created: HashMap<usize, bool> = HashMap::new();
    for &v in &order {
        let (slot, create) = pool.place(&values[v]);
        values[v].slot = slot;
        created.insert(v, create);
    }
    let steps = build_steps(values, &order, &created, n_passes);
    let peak = pool.held.iter().copied().max().unwrap_or(0);
    (
        pool.slots.into_iter().map(|(d, _)| d).collect(),
        steps,
        peak,
        lower,
    )
}

/// Bytes of the values live at each pass.
fn live_bytes(values: &[Value], n_passes: usize) -> Vec<u64> {
    let mut live = vec![0u64; n_passes.max(1)];
    for v in values.iter() {
        for l in &mut live[v.producer..=v.last_reader] {
            *l += v.desc.bytes();
        }
    }
    live
}

/// The slots made so far and the bytes held at each pass.
struct SlotPool {
    /// slot -> (desc, pass index after which it is free again)
    slots: Vec<(TextureDesc, usize)>,
    /// Bytes held at each pass: the live values, plus slots kept idle for reuse.
    held: Vec<u64>,
    /// The most bytes live at one pass.
    lower: u64,
    policy: ReusePolicy,
}

impl SlotPool {
    /// The slot of `v`: a free one reused (held idle until `v` is produced),
    /// or a new one. Returns the slot and whether it is created.
    fn place(&mut self, v: &Value) -> (usize, bool) {
        let (desc, start, end) = (v.desc, v.producer, v.last_reader);
        match self.reusable(desc, start) {
            Some(s) => {
                for h in &mut self.held[(self.slots[s].1 + 1)..start] {
                    *h += desc.bytes();
                }
                self.slots[s].1 = end;
                (s, false)
            }
            None => {
                self.slots.push((desc, end));
                (self.slots.len() - 1, true)
            }
        }
    }

    /// Free slots of `desc` at pass `start` that the policy lets be kept idle
    /// until then, the most recently freed first.
    fn reusable(&self, desc: TextureDesc, start: usize) -> Option<usize> {
        let bytes = desc.bytes();
        let mut best: Option<usize> = None;
        for (s, (sd, free_after)) in self.slots.iter().enumerate() {
            if *sd != desc || *free_after >= start {
                continue;
            }
            let idle = (free_after + 1)..start;
            let fits = match self.policy {
                ReusePolicy::Pool => true,
                ReusePolicy::MinPeak => idle.clone().all(|t| self.held[t] + bytes <= self.lower),
            };
            if fits && best.is_none_or(|b| self.slots[b].1 < *free_after) {
                best = Some(s);
            }
        }
        best
    }
}

/// For each pass: allocate the values it produces, run it, free the values it
/// reads last. A value's free releases its slot unless a later value reuses it.
fn build_steps(
    values: &[Value],
    order: &[usize],
    created: &HashMap<usize, bool>,
    n_passes: usize,
) -> Vec<Step> {
    let mut steps = Vec::new();
    for t in 0..n_passes {
        for &v in order {
            if values[v].producer == t {
                steps.push(Step::Alloc {
                    value: v,
                    slot: values[v].slot,
                    create: created[&v],
                });
            }
        }
        steps.push(Step::Run { pass: t });
        for &v in order {
            if values[v].last_reader == t {
                let reused = order
                    .iter()
                    .any(|&w| w != v && values[w].slot == values[v].slot && values[w].producer > t);
                steps.push(Step::Free {
                    value: v,
                    slot: values[v].slot,
                    release: !reused,
                });
            }
        }
    }
    steps
}
