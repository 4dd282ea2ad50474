//! Camera cuts: where a node (a camera's) jumps between two frames of a sequence
//! instead of moving, so that the second frame starts a new shot and temporal
//! effects must not carry history across it (docs/renderer.md, "Camera cuts").
//!
//! A jump is a discontinuity of the animation itself, known exactly from the
//! keys: a STEP channel changes its value at a key time in the interval, or the
//! clock of a looping playback wraps while a channel's last value differs from its
//! first. LINEAR and CUBICSPLINE channels move continuously, however fast.

use super::{ChannelPath, Interpolation, Playback};
use crate::scene::model::Scene;

impl Scene {
    /// Whether node `node` jumps between times `t0` and `t1 > t0` (seconds on the
    /// clock of `playback`): a STEP channel of a selected animation driving the
    /// translation, rotation or scale of the node or of one of its ancestors has
    /// a key in `(t0, t1]` whose value differs from the key before (the new value
    /// holds from its key time on), or the clock loops and wraps between `t0` and
    /// `t1` while such a channel (any interpolation) ends on another value than it
    /// starts with. Out-of-range nodes never jump.
    pub fn jumps(&self, playback: &Playback, node: usize, t0: f64, t1: f64) -> bool {
        if t1.partial_cmp(&t0) != Some(std::cmp::Ordering::Greater) || node >= self.nodes.len() {
            return false;
        }
        let mut chain = vec![node];
        let mut n = node;
        while let Some(p) = self.nodes[n].parent.filter(|&p| !chain.contains(&p)) {
            chain.push(p);
            n = p;
        }
        let (a, b) = (playback.local_time(self, t0), playback.local_time(self, t1));
        // the clock wrapped (looping): (a, end] and [start, b]
        let wrapped = b < a || (playback.looping && t1 - t0 >= self.animation_duration(playback));
        let inside = |t: f64| {
            if wrapped {
                t > a || t <= b
            } else {
                t > a && t <= b
            }
        };
        playback
            .animations(self)
            .iter()
            .flat_map(|anim| &anim.channels)
            .filter(|ch| chain.contains(&ch.node) && ch.path != ChannelPath::Weights)
            .any(|ch| {
                let s = &ch.sampler;
                let keys = s.times.len();
                if s.width() == 0 || keys == 0 {
                    return false;
                }
                if wrapped && s.key_value(0) != s.key_value(keys - 1) {
                    return true;
                }
                s.interpolation == Interpolation::Step
                    && (1..keys).any(|k| {
                        inside(f64::from(s.times[k])) && s.key_value(k) != s.key_value(k - 1)
                    })
            })
    }
}

#[cfg(test)]
mod tests {
    use crate::scene::animation::{Animation, Channel, Sampler};
    use crate::scene::node::Node;
    use crate::scene::{ChannelPath, Interpolation, Playback, Scene};

    /// Node 1 (child of node 0) carries the camera; node 0's translation is
    /// animated with `interpolation`: 0 until 1 s, then 5 (STEP) or moving there
    /// (LINEAR), and back to 0 at 2 s.
    fn scene(interpolation: Interpolation) -> Scene {
        Scene {
            nodes: vec![
                Node {
                    children: vec![1],
                    ..Default::default()
                },
                Node {
                    parent: Some(0),
                    ..Default::default()
                },
            ],
            animations: vec![Animation::new(
                "cut",
                vec![Channel {
                    node: 0,
                    path: ChannelPath::Translation,
                    sampler: Sampler {
                        interpolation,
                        times: vec![0.0, 1.0, 2.0],
                        values: vec![0.0, 0.0, 0.0, 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                    },
                }],
            )],
            ..Default::default()
        }
    }

    #[test]
    fn step_keys_cut_at_their_frame() {
        let s = scene(Interpolation::Step);
        let p = Playback::default();
        let dt = 1.0 / 30.0;
        assert!(!s.jumps(&p, 1, 0.5 - dt, 0.5));
        assert!(
            s.jumps(&p, 1, 1.0 - dt, 1.0),
            "the key at 1 s starts the frame at 1 s"
        );
        assert!(!s.jumps(&p, 1, 1.0, 1.0 + dt));
        assert!(s.jumps(&p, 1, 1.99, 2.01));
        assert!(s.jumps(&p, 0, 1.99, 2.01), "the animated node itself");
        assert!(!s.jumps(&p, 1, 3.0, 3.0 + dt), "held after the last key");
    }

    #[test]
    fn linear_keys_never_cut_but_a_looping_wrap_can() {
        let s = scene(Interpolation::Linear);
        let p = Playback::default();
        assert!(!s.jumps(&p, 1, 0.99, 1.01));
        // last value 0 = first value: the wrap is seamless
        let looping = Playback {
            looping: true,
            ..Playback::default()
        };
        assert!(!s.jumps(&looping, 1, 1.99, 2.01));
        let mut open = s.clone();
        open.animations[0].channels[0].sampler.values[6] = 1.0;
        assert!(
            open.jumps(&looping, 1, 1.99, 2.01),
            "ends at 1, starts at 0"
        );
        assert!(!open.jumps(&p, 1, 1.99, 2.01), "without looping it holds");
    }
}
