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
    // Bytes live at each pass.
    let mut live = vec![0u64; n_passes.max(1)];
    for v in values.iter() {
        for l in &mut live[v.producer..=v.last_reader] {
            *l += v.desc.bytes();
        }
    }
    let lower = live.iter().copied().max().unwrap_or(0);
    let mut held = live.clone();
    // slot -> (desc, pass index after which it is free again)
    let mut slots: Vec<(TextureDesc, usize)> = Vec::new();
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by_key(|&v| (values[v].producer, v));
    let mut first_use = Vec::new();
    for &v in &order {
        let (desc, start, end) = (values[v].desc, values[v].producer, values[v].last_reader);
        let bytes = desc.bytes();
        // Free slots of the same descriptor, the most recently freed first.
        let mut best: Option<usize> = None;
        for (s, (sd, free_after)) in slots.iter().enumerate() {
            if *sd != desc || *free_after >= start {
                continue;
            }
            let idle = (free_after + 1)..start;
            let fits = match policy {
                ReusePolicy::Pool => true,
                ReusePolicy::MinPeak => idle.clone().all(|t| held[t] + bytes <= lower),
            };
            if fits && best.is_none_or(|b| slots[b].1 < *free_after) {
                best = Some(s);
            }
        }
        let slot = match best {
            Some(s) => {
                for h in &mut held[(slots[s].1 + 1)..start] {
                    *h += bytes;
                }
                slots[s].1 = end;
                first_use.push(false);
                s
            }
            None => {
                slots.push((desc, end));
                first_use.push(true);
                slots.len() - 1
            }
        };
        values[v].slot = slot;
    }
    // A value's free releases its slot unless a later value reuses it.
    let mut next_user: HashMap<usize, usize> = HashMap::new();
    for &v in &order {
        next_user.entry(values[v].slot).or_insert(v);
    }
    let mut steps = Vec::new();
    let created: HashMap<usize, bool> = order
        .iter()
        .zip(first_use.iter())
        .map(|(&v, &c)| (v, c))
        .collect();
    for t in 0..n_passes {
        for &v in &order {
            if values[v].producer == t {
                steps.push(Step::Alloc {
                    value: v,
                    slot: values[v].slot,
                    create: created[&v],
                });
            }
        }
        steps.push(Step::Run { pass: t });
        for &v in &order {
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
    let peak = held.iter().copied().max().unwrap_or(0);
    (
        slots.into_iter().map(|(d, _)| d).collect(),
        steps,
        peak,
        lower,
    )
}
