//! The frames-per-second readout of a viewer: the frames shown over the last
//! second ([`FpsCounter::WINDOW`]) and the mean time one of them took to make, so
//! the figure is steady enough to read and follows a change within a second.
//! Plain time arithmetic, no GPU: the caller says when each frame ended and how
//! long it took ([`FpsCounter::tick`]).

use std::collections::VecDeque;
use std::time::{Duration, Instant};

/// The smoothed rate and frame time at one moment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FpsReading {
    /// Frames per second over the window.
    pub fps: f64,
    /// Mean time of one frame's work (effect, panel, image pass, present), in ms.
    pub frame_ms: f64,
}

impl FpsReading {
    /// As the viewer's panel shows it: `59.8 fps · 3.1 ms per frame`.
    pub fn text(&self) -> String {
        format!("{:.1} fps · {:.1} ms per frame", self.fps, self.frame_ms)
    }
}

/// The frames of the last second: when each ended, and how long it took.
#[derive(Debug, Default, Clone)]
pub struct FpsCounter {
    frames: VecDeque<(Instant, Duration)>,
}

impl FpsCounter {
    /// How far back frames are counted.
    pub const WINDOW: Duration = Duration::from_secs(1);

    /// A frame ended at `end`, after `took`; frames older than the window go,
    /// but for the last two (frames slower than the window still give a rate).
    pub fn tick(&mut self, end: Instant, took: Duration) {
        self.frames.push_back((end, took));
        while self.frames.len() > 2
            && self
                .frames
                .front()
                .is_some_and(|(t, _)| end.duration_since(*t) > Self::WINDOW)
        {
            self.frames.pop_front();
        }
    }

    /// The rate over the window (intervals between the frames kept) and the mean
    /// frame time; `None` until two frames were shown.
    pub fn reading(&self) -> Option<FpsReading> {
        let (first, _) = self.frames.front()?;
        let (last, _) = self.frames.back()?;
        let span = last.duration_since(*first).as_secs_f64();
        let intervals = self.frames.len() - 1;
        if intervals == 0 || span <= 0.0 {
            return None;
        }
        let work: Duration = self.frames.iter().map(|(_, d)| *d).sum();
        Some(FpsReading {
            fps: intervals as f64 / span,
            frame_ms: work.as_secs_f64() * 1e3 / self.frames.len() as f64,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` frames `every` apart from `start`, each taking `took`.
    fn run(c: &mut FpsCounter, start: Instant, n: u32, every: Duration, took: Duration) -> Instant {
        let mut t = start;
        for _ in 0..n {
            t += every;
            c.tick(t, took);
        }
        t
    }

    #[test]
    fn no_reading_before_two_frames() {
        let mut c = FpsCounter::default();
        assert_eq!(c.reading(), None);
        c.tick(Instant::now(), Duration::from_millis(3));
        assert_eq!(c.reading(), None);
    }

    #[test]
    fn steady_frames_give_their_rate_and_time() {
        let mut c = FpsCounter::default();
        let every = Duration::from_micros(16_667);
        run(&mut c, Instant::now(), 120, every, Duration::from_millis(4));
        let r = c.reading().expect("frames");
        assert!((r.fps - 60.0).abs() < 0.1, "{r:?}");
        assert!((r.frame_ms - 4.0).abs() < 1e-9, "{r:?}");
        assert_eq!(r.text(), "60.0 fps · 4.0 ms per frame");
    }

    #[test]
    fn the_reading_forgets_frames_older_than_a_second() {
        let mut c = FpsCounter::default();
        let t = run(
            &mut c,
            Instant::now(),
            100,
            Duration::from_millis(10),
            Duration::from_millis(9),
        );
        // Slower now: after more than a second of 20 fps only new frames count.
        run(
            &mut c,
            t,
            25,
            Duration::from_millis(50),
            Duration::from_millis(2),
        );
        let r = c.reading().expect("frames");
        assert!((r.fps - 20.0).abs() < 1e-6, "{r:?}");
        assert!((r.frame_ms - 2.0).abs() < 1e-9, "{r:?}");
    }

    #[test]
    fn frames_slower_than_the_window_give_their_rate() {
        let mut c = FpsCounter::default();
        let every = Duration::from_millis(2500);
        run(
            &mut c,
            Instant::now(),
            3,
            every,
            Duration::from_millis(2400),
        );
        let r = c.reading().expect("frames");
        assert!((r.fps - 0.4).abs() < 1e-9, "{r:?}");
        assert!((r.frame_ms - 2400.0).abs() < 1e-6, "{r:?}");
    }

    #[test]
    fn a_change_shows_smoothed_within_the_window() {
        let mut c = FpsCounter::default();
        let t = run(
            &mut c,
            Instant::now(),
            60,
            Duration::from_millis(10),
            Duration::from_millis(1),
        );
        // Half a second at 20 fps after 100 fps: between the two.
        run(
            &mut c,
            t,
            10,
            Duration::from_millis(50),
            Duration::from_millis(1),
        );
        let r = c.reading().expect("frames");
        assert!(r.fps > 20.0 && r.fps < 100.0, "{r:?}");
    }
}
