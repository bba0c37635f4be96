//! The fleet replay: the instant of a shown fleet result the map draws, and
//! whether it advances by itself. Its own state; the result's duration
//! (`end`) comes from the caller, which knows what is shown.

use std::time::Duration;

#[derive(Debug, Clone, Default, PartialEq)]
pub struct Replay {
    /// The instant shown; None = the end.
    at: Option<f64>,
    playing: bool,
}

impl Replay {
    pub fn is_playing(&self) -> bool {
        self.playing
    }

    /// The instant drawn for a result lasting `end` seconds.
    pub fn time(&self, end: f64) -> f64 {
        self.at.unwrap_or(end).min(end)
    }

    /// Moves by `seconds` within [0, end], and pauses.
    pub fn scrub(&mut self, seconds: f64, end: f64) {
        let t = self.at.unwrap_or(end) + seconds;
        self.at = Some(t.clamp(0.0, end));
        self.playing = false;
    }

    /// Plays (from the start when at the end) or pauses.
    pub fn toggle(&mut self, end: f64) {
        if !self.playing && self.at.is_none_or(|t| t >= end) {
            self.at = Some(0.0);
        }
        self.playing = !self.playing;
    }

    /// Advances a playing replay by `elapsed`; it stops at `end`.
    pub fn advance(&mut self, elapsed: Duration, end: f64) {
        if self.playing {
            let t = self.at.unwrap_or(0.0) + elapsed.as_secs_f64();
            self.at = Some(t.min(end));
            if t >= end {
                self.playing = false;
            }
        }
    }

    /// Back to the end, paused (another result is shown).
    pub fn reset(&mut self) {
        *self = Replay::default();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn play_runs_from_the_start_to_the_end_and_stops() {
        let mut r = Replay::default();
        assert_eq!(r.time(10.0), 10.0, "the end until played");
        r.toggle(10.0);
        assert!(r.is_playing());
        assert_eq!(r.time(10.0), 0.0);
        r.advance(Duration::from_secs(4), 10.0);
        assert_eq!(r.time(10.0), 4.0);
        r.advance(Duration::from_secs(7), 10.0);
        assert_eq!((r.time(10.0), r.is_playing()), (10.0, false));
    }

    #[test]
    fn scrubbing_pauses_and_stays_within_the_result() {
        let mut r = Replay::default();
        r.toggle(10.0);
        r.scrub(-3.0, 10.0);
        assert_eq!((r.time(10.0), r.is_playing()), (0.0, false));
        r.scrub(2.5, 10.0);
        assert_eq!(r.time(10.0), 2.5);
        r.scrub(100.0, 10.0);
        assert_eq!(r.time(10.0), 10.0);
        r.reset();
        assert_eq!(r, Replay::default());
    }
}
