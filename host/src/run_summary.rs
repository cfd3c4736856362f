//! What `host run` and `host bench` report of a run: its counters and its
//! measured speed.

use serde::Serialize;
use sim::control::Controller;
use sim::sensors::SensorModel;
use sim::simulation::{Simulation, Totals};
use std::fmt;
use std::time::Instant;

/// The figures `host run` prints.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunSummary {
    /// Steps run.
    pub steps: u64,
    /// Episodes that formed the shape.
    pub formations: u64,
    /// Episodes reset at the stuck limit.
    pub stuck: u64,
    /// Robot-robot collisions per 1000 steps.
    pub collisions_per_1000: f64,
    /// Mean Eval at the formation checks.
    pub mean_eval: f64,
    /// Wall-clock speed of the run.
    pub steps_per_second: f64,
}

impl RunSummary {
    /// The summary of a run's counters, `seconds` of wall time long.
    pub fn new(totals: &Totals, seconds: f64) -> RunSummary {
        RunSummary {
            steps: totals.steps,
            formations: totals.formations,
            stuck: totals.stuck,
            collisions_per_1000: totals.collisions_per_1000(),
            mean_eval: totals.mean_eval(),
            steps_per_second: if seconds > 0.0 {
                totals.steps as f64 / seconds
            } else {
                f64::INFINITY
            },
        }
    }
}

impl fmt::Display for RunSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "steps                {}", self.steps)?;
        writeln!(f, "formations           {}", self.formations)?;
        writeln!(f, "stuck episodes       {}", self.stuck)?;
        writeln!(f, "collisions per 1000  {:.1}", self.collisions_per_1000)?;
        writeln!(f, "mean Eval            {:.4}", self.mean_eval)?;
        write!(f, "steps per second     {:.0}", self.steps_per_second)
    }
}

/// Runs `steps` steps and summarises them with the measured speed.
pub fn run_timed<S: SensorModel, C: Controller + ?Sized>(
    sim: &mut Simulation<S>,
    controller: &mut C,
    steps: u64,
) -> RunSummary {
    let start = Instant::now();
    sim.run(controller, steps);
    RunSummary::new(sim.totals(), start.elapsed().as_secs_f64())
}
