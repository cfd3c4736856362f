//! Fault flags over a run: frames with each flag, and its episodes (runs
//! of consecutive frames with the flag set).

use super::report::{FaultCount, FaultEpisode, LISTED};
use shared::{Faults, LogFrame};

/// Fault counts and episodes of the frames seen so far.
#[derive(Clone, Debug)]
pub struct FaultTracker {
    /// Frames with any fault flag.
    pub fault_frames: u64,
    /// Per flag, in [`Faults::NAMED`] order.
    pub faults: Vec<FaultCount>,
    open: Vec<Option<FaultEpisode>>,
    /// The first [`LISTED`] episodes by start (after [`FaultTracker::finish`]).
    pub first_episodes: Vec<FaultEpisode>,
}

impl Default for FaultTracker {
    fn default() -> FaultTracker {
        FaultTracker {
            fault_frames: 0,
            faults: Faults::NAMED
                .iter()
                .map(|(_, name)| FaultCount {
                    fault: name,
                    frames: 0,
                    episodes: 0,
                })
                .collect(),
            open: vec![None; Faults::NAMED.len()],
            first_episodes: Vec::new(),
        }
    }
}

impl FaultTracker {
    /// Adds one frame's flags.
    pub fn frame(&mut self, f: &LogFrame) {
        if !f.faults.is_empty() {
            self.fault_frames += 1;
        }
        for (i, (flag, name)) in Faults::NAMED.iter().enumerate() {
            if f.faults.contains(*flag) {
                self.faults[i].frames += 1;
                match &mut self.open[i] {
                    Some(e) => {
                        e.last_tick = f.tick;
                        e.frames += 1;
                    }
                    open @ None => {
                        self.faults[i].episodes += 1;
                        *open = Some(FaultEpisode {
                            fault: name,
                            first_tick: f.tick,
                            last_tick: f.tick,
                            frames: 1,
                        });
                    }
                }
            } else if let Some(e) = self.open[i].take() {
                self.close(e);
            }
        }
    }

    /// Closes the episodes still open at the end of the run.
    pub fn finish(&mut self) {
        for i in 0..self.open.len() {
            if let Some(e) = self.open[i].take() {
                self.close(e);
            }
        }
    }

    fn close(&mut self, e: FaultEpisode) {
        // Episodes close in end order; keep the first LISTED by start.
        self.first_episodes.push(e);
        self.first_episodes.sort_by_key(|e| e.first_tick);
        self.first_episodes.truncate(LISTED);
    }
}
