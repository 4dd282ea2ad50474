//! The ffmpeg and ffprobe child processes: finding them on `PATH`, starting them in
//! their own process group (a Ctrl-C in the terminal reaches fxrun alone, which ends
//! them itself), keeping the last lines of their stderr, and the command lines `-v`
//! prints.

use super::VideoError;
use std::collections::VecDeque;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

/// Lines of stderr kept for an error message.
const TAIL_LINES: usize = 12;
/// Longest stderr line kept (characters).
const TAIL_LINE_CHARS: usize = 400;

/// The full path of `program` in a folder of `PATH` (an executable file), if any.
pub fn find_program(program: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .filter(|d| !d.as_os_str().is_empty())
        .flat_map(|d| {
            let plain = d.join(program);
            let exe = d.join(format!("{program}.exe"));
            [plain, exe]
        })
        .find(|p| is_executable(p))
}

fn is_executable(p: &Path) -> bool {
    let Ok(m) = std::fs::metadata(p) else {
        return false;
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        m.is_file() && m.permissions().mode() & 0o111 != 0
    }
    #[cfg(not(unix))]
    {
        m.is_file()
    }
}

/// [`find_program`], or [`VideoError::Missing`] naming `file` (the video file that
/// needed it).
pub(super) fn require(program: &'static str, file: &Path) -> Result<PathBuf, VideoError> {
    find_program(program).ok_or_else(|| VideoError::Missing {
        path: file.to_path_buf(),
        program,
    })
}

/// A command line as a shell would take it back: arguments with spaces or shell
/// characters in single quotes.
pub fn shell_line(program: &str, args: &[String]) -> String {
    let quote = |a: &str| -> String {
        let plain = !a.is_empty()
            && a.bytes()
                .all(|b| b.is_ascii_alphanumeric() || b"-_./:=+,@%^".contains(&b));
        if plain {
            a.to_string()
        } else {
            format!("'{}'", a.replace('\'', "'\\''"))
        }
    };
    std::iter::once(program)
        .chain(args.iter().map(String::as_str))
        .map(quote)
        .collect::<Vec<_>>()
        .join(" ")
}

/// A path as an ffmpeg argument: ffmpeg reads `name:rest` as a protocol and `-x` as an
/// option, so such names get the `file:` protocol.
pub(super) fn file_arg(p: &Path) -> String {
    let s = p.to_string_lossy().into_owned();
    if s.contains(':') || s.starts_with('-') {
        format!("file:{s}")
    } else {
        s
    }
}

/// A running child whose stderr is collected on a thread (the last [`TAIL_LINES`]
/// lines). Dropping it kills the child if it still runs, and waits for it.
pub(super) struct Child {
    pub(super) child: std::process::Child,
    /// What it is, for messages: `ffmpeg`, `ffprobe`.
    pub(super) program: &'static str,
    tail: Arc<Mutex<VecDeque<String>>>,
    reader: Option<JoinHandle<()>>,
    status: Option<ExitStatus>,
}

impl Child {
    /// Start `path` with `args`; stdin and stdout as given, stderr collected.
    pub(super) fn spawn(
        program: &'static str,
        path: &Path,
        args: &[String],
        stdin: Stdio,
        stdout: Stdio,
    ) -> std::io::Result<Child> {
        let mut cmd = Command::new(path);
        cmd.args(args)
            .stdin(stdin)
            .stdout(stdout)
            .stderr(Stdio::piped());
        // Its own process group: the terminal's Ctrl-C goes to fxrun, which stops
        // the run and ends its children (an encoder is killed, its temporary removed).
        #[cfg(unix)]
        {
            use std::os::unix::process::CommandExt;
            cmd.process_group(0);
        }
        let mut child = cmd.spawn()?;
        let tail = Arc::new(Mutex::new(VecDeque::new()));
        let reader = child.stderr.take().map(|err| {
            let tail = tail.clone();
            std::thread::Builder::new()
                .name(format!("{program} stderr"))
                .spawn(move || {
                    for line in BufReader::new(err).split(b'\n') {
                        let Ok(line) = line else { break };
                        let text = String::from_utf8_lossy(&line);
                        let text = text.trim_end();
                        if text.is_empty() {
                            continue;
                        }
                        let mut t = tail.lock().unwrap_or_else(|e| e.into_inner());
                        if t.len() == TAIL_LINES {
                            t.pop_front();
                        }
                        t.push_back(text.chars().take(TAIL_LINE_CHARS).collect());
                    }
                })
        });
        let reader = match reader {
            Some(Ok(h)) => Some(h),
            Some(Err(e)) => {
                let _ = child.kill();
                let _ = child.wait();
                return Err(e);
            }
            None => None,
        };
        Ok(Child {
            child,
            program,
            tail,
            reader,
            status: None,
        })
    }

    /// Wait for the child to end (and for its stderr to be read).
    pub(super) fn wait(&mut self) -> std::io::Result<ExitStatus> {
        if let Some(s) = self.status {
            return Ok(s);
        }
        let s = self.child.wait()?;
        self.status = Some(s);
        if let Some(h) = self.reader.take() {
            let _ = h.join();
        }
        Ok(s)
    }

    /// The exit status if the child has ended, without waiting.
    pub(super) fn try_status(&mut self) -> Option<ExitStatus> {
        if self.status.is_none() {
            if let Ok(Some(_)) = self.child.try_wait() {
                // Reaped: `wait` returns the status at once and joins the reader.
                return self.wait().ok();
            }
        }
        self.status
    }

    /// Kill the child (if it runs) and wait for it.
    pub(super) fn kill(&mut self) {
        if self.status.is_none() {
            let _ = self.child.kill();
            let _ = self.wait();
        }
    }

    /// The last lines of stderr, each indented and prefixed with the program's name.
    pub(super) fn tail(&self) -> String {
        let t = self.tail.lock().unwrap_or_else(|e| e.into_inner());
        if t.is_empty() {
            return format!("  ({} printed nothing on stderr)", self.program);
        }
        t.iter()
            .map(|l| format!("  {}: {l}", self.program))
            .collect::<Vec<_>>()
            .join("\n")
    }

    /// Log the stderr lines of a child that succeeded (warnings it printed), prefixed.
    pub(super) fn log_stderr(&self, what: &str) {
        let t = self.tail.lock().unwrap_or_else(|e| e.into_inner());
        for l in t.iter() {
            log::warn!("{} ({what}): {l}", self.program);
        }
    }
}

impl Drop for Child {
    fn drop(&mut self) {
        self.kill();
    }
}

/// An exit status in words: `exit status 1`, `killed by signal 9`.
pub(super) fn status_text(s: ExitStatus) -> String {
    if let Some(c) = s.code() {
        return format!("exit status {c}");
    }
    #[cfg(unix)]
    {
        use std::os::unix::process::ExitStatusExt;
        if let Some(sig) = s.signal() {
            return format!("killed by signal {sig}");
        }
    }
    s.to_string()
}
