//! The run's timeline: frames, first and last tick, lost frames, restarts,
//! host time, and frames per mode.

use super::report::ModeCounts;
use shared::LogFrame;

/// Ticks and modes of the frames seen so far.
#[derive(Clone, Debug, Default)]
pub struct Timeline {
    /// Frames decoded.
    pub frames: u64,
    /// First and last tick.
    pub ticks: Option<(u32, u32)>,
    last_tick: Option<u32>,
    /// Ticks missing between consecutive frames.
    pub missing_ticks: u64,
    /// Times the tick went backwards.
    pub restarts: u64,
    /// Host time of the first and the last record, us.
    pub host_times: Option<(u64, u64)>,
    /// Frames per mode.
    pub modes: ModeCounts,
}

impl Timeline {
    /// Adds one frame, recorded at `host_time_us` if the log says.
    pub fn frame(&mut self, f: &LogFrame, host_time_us: Option<u64>) {
        self.frames += 1;
        if let Some(t) = host_time_us {
            self.host_times = Some(self.host_times.map_or((t, t), |(first, _)| (first, t)));
        }
        self.ticks = Some(
            self.ticks
                .map_or((f.tick, f.tick), |(first, _)| (first, f.tick)),
        );
        if let Some(last) = self.last_tick {
            if f.tick > last {
                self.missing_ticks += u64::from(f.tick - last - 1);
            } else {
                self.restarts += 1;
            }
        }
        self.last_tick = Some(f.tick);
        self.modes.count(f.mode);
    }
}
