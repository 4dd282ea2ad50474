//! Scripted mode, for tests and bug reports: `--view-frames N` shows N frames
//! (a sequence advances one frame per frame shown; the effect of a still or a
//! scene is recorded again every frame), writes `--screenshot FILE` and exits 0.
//! `--view-do K:ACTION` runs ACTION after frame K (1-based) was shown, through the
//! code the panel and the keys use:
//!
//! - `set NAME=VALUE`, `reset NAME`: a parameter, as the panel's controls;
//! - `inspect PASS` (a pass's path or last part, `output`, `input`, `aux:NAME`);
//! - `key KEY` (`Right`, `Left`, `Home`, `Space`, `F`, `1`, `B`, `Tab`, `P`, ...);
//! - `copy-set`: print the values as `--set` arguments (the panel's button);
//! - `wait-reload`: wait (at most 10 minutes) until a watched file changed and the
//!   effect was compiled again (or failed to): the n-th `wait-reload` waits for the
//!   n-th reload since the start, which may have happened already;
//! - `pause`: print where the window and its image are on the screen, and wait for
//!   a line on standard input (for a screenshot of the display).

use std::collections::VecDeque;

/// One scripted action.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Action {
    Set(String, String),
    Reset(String),
    Inspect(String),
    Key(String),
    CopySet,
    WaitReload,
    Pause,
}

impl std::fmt::Display for Action {
    /// As written after `K:` in `--view-do`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Action::Set(n, v) => write!(f, "set {n}={v}"),
            Action::Reset(n) => write!(f, "reset {n}"),
            Action::Inspect(n) => write!(f, "inspect {n}"),
            Action::Key(k) => write!(f, "key {k}"),
            Action::CopySet => f.write_str("copy-set"),
            Action::WaitReload => f.write_str("wait-reload"),
            Action::Pause => f.write_str("pause"),
        }
    }
}

/// Parse `K:ACTION`.
pub(super) fn parse(arg: &str) -> Result<(u64, Action), String> {
    let bad = |why: &str| format!("--view-do {arg}: {why}");
    let (k, action) = arg
        .split_once(':')
        .ok_or_else(|| bad("expected FRAME:ACTION, e.g. 2:set threshold=0.5"))?;
    let k: u64 = k
        .trim()
        .parse()
        .ok()
        .filter(|k| *k >= 1)
        .ok_or_else(|| bad("the frame is a number from 1"))?;
    let action = action.trim();
    let (verb, rest) = action.split_once(' ').unwrap_or((action, ""));
    let rest = rest.trim();
    let need = |what: &str| {
        if rest.is_empty() {
            Err(bad(&format!("`{verb}` needs {what}")))
        } else {
            Ok(rest.to_string())
        }
    };
    let a = match verb {
        "set" => {
            let (n, v) = rest
                .split_once('=')
                .ok_or_else(|| bad("`set` needs NAME=VALUE"))?;
            Action::Set(n.trim().to_string(), v.trim().to_string())
        }
        "reset" => Action::Reset(need("a parameter name")?),
        "inspect" => Action::Inspect(need("a pass name, output, input or aux:NAME")?),
        "key" => {
            let k = need("a key name")?;
            if super::commands::named_command(&k).is_none() {
                return Err(bad(&format!(
                    "`{k}` is no command key (Right, Left, PageDown, PageUp, Up, Down, Home, \
                     Space, Tab, Esc, F12, F, 1, +, -, B, P, H; the fly keys W A S D E Q \
                     act while held and are not scripted)"
                )));
            }
            Action::Key(k)
        }
        "copy-set" => Action::CopySet,
        "wait-reload" => Action::WaitReload,
        "pause" => Action::Pause,
        _ => {
            return Err(bad(
                "unknown action (set, reset, inspect, key, copy-set, wait-reload, pause)",
            ))
        }
    };
    Ok((k, a))
}

/// The scripted run: frames to show and actions to take.
pub(super) struct Script {
    pub frames: u64,
    pub shown: u64,
    actions: VecDeque<(u64, Action)>,
}

impl Script {
    pub fn new(frames: u64, mut actions: Vec<(u64, Action)>) -> Self {
        actions.sort_by_key(|(k, _)| *k);
        Script {
            frames,
            shown: 0,
            actions: actions.into(),
        }
    }

    /// Frame `shown` was shown: the actions due now.
    pub fn due(&mut self) -> Vec<Action> {
        let mut out = Vec::new();
        while self.actions.front().is_some_and(|(k, _)| *k <= self.shown) {
            out.push(self.actions.pop_front().expect("front exists").1);
        }
        out
    }

    /// All frames shown (and no action left)?
    pub fn done(&self) -> bool {
        self.shown >= self.frames && self.actions.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn actions_parse_and_come_in_frame_order() {
        assert_eq!(
            parse("2:set brightPass.threshold=0.5"),
            Ok((2, Action::Set("brightPass.threshold".into(), "0.5".into())))
        );
        assert_eq!(
            parse("1:inspect blurX"),
            Ok((1, Action::Inspect("blurX".into())))
        );
        assert_eq!(parse("3:wait-reload"), Ok((3, Action::WaitReload)));
        assert!(parse("0:pause").is_err());
        assert!(parse("2:set x").is_err());
        assert!(parse("2:dance").is_err());
        assert_eq!(
            parse("1:key pagedown"),
            Ok((1, Action::Key("pagedown".into())))
        );
        let w = parse("1:key W").unwrap_err();
        assert!(
            w.starts_with("--view-do 1:key W: `W` is no command key"),
            "{w}"
        );
        assert_eq!(
            Action::Set("a.b".into(), "1".into()).to_string(),
            "set a.b=1"
        );
        let mut s = Script::new(3, vec![(2, Action::Pause), (1, Action::CopySet)]);
        s.shown = 1;
        assert_eq!(s.due(), vec![Action::CopySet]);
        s.shown = 3;
        assert_eq!(s.due(), vec![Action::Pause]);
        assert!(s.done());
    }
}
