//! Hot reload: the files the effect was compiled from (the `.fx` files, their
//! `INCLUDE`s, the pass shaders and their `#include`s) and a single input image
//! are watched with `--watch`'s watcher ([`crate::watch::watched_files`],
//! [`crate::watch::wait_for_change`]); a change wakes the window's event loop,
//! which compiles and plans again, and shows the errors in the window while
//! keeping the last good image.

use super::UserEvent;
use crate::watch::{wait_for_change, watched_files, Change};
use crate::Cli;
use notify::{RecursiveMode, Watcher as _};
use std::collections::HashSet;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use winit::event_loop::EventLoopProxy;

/// A watching thread; dropping it stops the thread.
pub(super) struct Reloader {
    stop: Arc<AtomicBool>,
    pub files: HashSet<PathBuf>,
}

impl Drop for Reloader {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
    }
}

impl Reloader {
    /// Watch the files `cli`'s effect reads (plus `extra`). The watches are in place
    /// when this returns, so a change made after it is seen.
    pub fn start(
        cli: &Cli,
        extra: &HashSet<PathBuf>,
        proxy: EventLoopProxy<UserEvent>,
    ) -> Result<Reloader, String> {
        let mut files: HashSet<PathBuf> = watched_files(cli).into_iter().collect();
        files.extend(extra.iter().cloned());
        let (tx, rx) = std::sync::mpsc::channel();
        let mut watcher = notify::recommended_watcher(tx).map_err(|e| e.to_string())?;
        let dirs: HashSet<PathBuf> = files
            .iter()
            .filter_map(|f| f.parent().map(|p| p.to_path_buf()))
            .collect();
        for d in &dirs {
            if let Err(e) = watcher.watch(d, RecursiveMode::NonRecursive) {
                log::warn!("--view: cannot watch {}: {e}", d.display());
            }
        }
        let stop = Arc::new(AtomicBool::new(false));
        let halt = Arc::clone(&stop);
        let watched = files.clone();
        std::thread::spawn(move || {
            let _watcher = watcher;
            loop {
                match wait_for_change(&rx, &watched, &[], &halt) {
                    Change::Stop => break,
                    Change::Script | Change::Inputs => {
                        if proxy.send_event(UserEvent::FilesChanged).is_err() {
                            break;
                        }
                    }
                }
            }
        });
        Ok(Reloader { stop, files })
    }
}
