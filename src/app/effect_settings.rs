//! What an effect was compiled with (the chain and its overrides) and the pass
//! parameters set on it ([`super::Effect::set`]), applied again each time it
//! is planned.

use crate::gpu::executor::Prepared;
use crate::graph::Override;
use std::collections::BTreeMap;

/// What an effect was compiled with and the pass parameters set on it.
#[derive(Clone)]
pub(super) struct Settings {
    pub(super) chain: Vec<String>,
    pub(super) overrides: Vec<Override>,
    /// Pass parameters set, by full name (`glow/brightPass.threshold`), with the
    /// WGSL type they were set as.
    pub(super) pass_sets: BTreeMap<String, (Vec<f64>, String)>,
    /// The pass parameters as the effect gives them (before `pass_sets`).
    pub(super) effect_values: BTreeMap<String, Vec<f64>>,
}

impl Settings {
    pub(super) fn new(chain: Vec<String>, overrides: Vec<Override>) -> Settings {
        Settings {
            chain,
            overrides,
            pass_sets: BTreeMap::new(),
            effect_values: BTreeMap::new(),
        }
    }

    /// Take over the pass parameters set on an earlier compile of the chain.
    pub(super) fn keep_pass_settings(&mut self, old: &Settings) {
        self.pass_sets = old.pass_sets.clone();
    }

    /// After planning: note the values the effect gives and apply the pass
    /// parameters set; those that no longer exist (or changed type) are dropped
    /// and logged.
    pub(super) fn apply(&mut self, prepared: &mut Prepared) {
        let params = prepared.params();
        self.effect_values = params
            .iter()
            .map(|p| (p.name.clone(), p.value.clone()))
            .collect();
        let mut dropped = Vec::new();
        self.pass_sets.retain(|name, (value, ty)| {
            let ok = params.iter().any(|p| &p.name == name && &p.ty == ty)
                && prepared.set_param(name, value).is_ok();
            if !ok {
                dropped.push(name.clone());
            }
            ok
        });
        if !dropped.is_empty() {
            log::info!("parameters no longer in the effect: {}", dropped.join(", "));
        }
    }
}
