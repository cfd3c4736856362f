//! The plausible range of every physical and numeric setting, in one
//! table ([`SECTIONS`]), and reading files no larger than their format
//! can be ([`read_file`]).
//!
//! A setting outside its range is refused before anything is allocated or
//! stepped, with a [`RangeError`] that names the key, the value and the
//! range: `pucks = 0: outside its plausible range [1, 100000] (a formation
//! needs pucks)`. The ranges are wide (a setting inside one may still be
//! refused by a rule between settings, such as more bodies than fit the
//! arena) but close enough that a unit slip (millimetres for metres, a
//! radius given in metres) or a stray exponent is caught, and that no one
//! setting inside them makes a tool allocate more than about 1 GB.
//!
//! Notation: `[a, b]` includes both bounds, `(a, b]` excludes `a`. Keys
//! are as config files and the Python environments' keyword arguments
//! spell them (`world.pucks`, `arena.screen_mm`, `pucks`), which `host`'s
//! flags share (`--pucks` sets `pucks`); a flag no file has keeps its
//! dashes (`--scale`), and a key of the form `a / b` is a ratio of two
//! settings. `docs/ranges.md` shows the table (a test checks that it
//! is this one).
//!
//! The table lives in `base`, the first room, because the field images
//! (room 2, `fields`) are checked against it as well as the settings of
//! every later room and of `host` and the Python package.

use std::fmt;
use std::io::Read;
use std::path::Path;

/// One setting's plausible range.
#[derive(Debug, PartialEq)]
pub struct Range {
    /// The keys it is checked as; the first names the row.
    pub keys: &'static [&'static str],
    /// The least plausible value.
    pub min: f64,
    /// Whether `min` itself is refused (a length must be positive).
    pub min_open: bool,
    /// The greatest plausible value.
    pub max: f64,
    /// Whether `max` itself is refused.
    pub max_open: bool,
    /// The unit of the value and bounds (empty for a plain number).
    pub unit: &'static str,
    /// Why these bounds.
    pub why: &'static str,
}

impl Range {
    const fn closed(
        keys: &'static [&'static str],
        min: f64,
        max: f64,
        unit: &'static str,
        why: &'static str,
    ) -> Range {
        Range {
            keys,
            min,
            min_open: false,
            max,
            max_open: false,
            unit,
            why,
        }
    }

    /// This range without its lower bound.
    const fn above_min(self) -> Range {
        Range {
            min_open: true,
            ..self
        }
    }

    /// This range without its upper bound.
    const fn below_max(self) -> Range {
        Range {
            max_open: true,
            ..self
        }
    }

    /// The key that names the row.
    pub fn key(&self) -> &'static str {
        self.keys[0]
    }

    /// Whether `value` is a number inside the range.
    pub fn contains(&self, value: f64) -> bool {
        let above = if self.min_open {
            value > self.min
        } else {
            value >= self.min
        };
        let below = if self.max_open {
            value < self.max
        } else {
            value <= self.max
        };
        above && below
    }

    /// Checks `value` of the row's own key.
    pub fn check(&'static self, value: f64) -> Result<(), RangeError> {
        self.check_as(self.key(), value)
    }

    /// Checks `value` of `key` (one of the row's keys, maybe with an index:
    /// `field.mounts[0].forward_mm`).
    pub fn check_as(&'static self, key: &str, value: f64) -> Result<(), RangeError> {
        if self.contains(value) {
            Ok(())
        } else {
            Err(RangeError {
                key: key.to_string(),
                value,
                range: self,
            })
        }
    }

    /// Checks a count or step number of `key`.
    pub fn check_count(&'static self, key: &str, value: u64) -> Result<(), RangeError> {
        self.check_as(key, value as f64)
    }
}

impl fmt::Display for Range {
    /// `[1, 100000] steps`, `(0, 1000] mm`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}{}, {}{}",
            if self.min_open { '(' } else { '[' },
            number(self.min),
            number(self.max),
            if self.max_open { ')' } else { ']' }
        )?;
        if !self.unit.is_empty() {
            write!(f, " {}", self.unit)?;
        }
        Ok(())
    }
}

/// A value outside its plausible range.
#[derive(Clone, Debug, PartialEq)]
pub struct RangeError {
    /// The key as the user gave it.
    pub key: String,
    /// The value.
    pub value: f64,
    /// Its range.
    pub range: &'static Range,
}

impl fmt::Display for RangeError {
    /// `pucks = 0: outside its plausible range [1, 100000] (...)`; a
    /// command-line flag as it is typed, with the range's unit:
    /// `--hold 1e9 s: outside its plausible range [0.5, 20] s (...)`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (key, value) = (&self.key, number(self.value));
        if !key.starts_with("--") {
            write!(f, "{key} = {value}")?;
        } else if self.range.unit.is_empty() {
            write!(f, "{key} {value}")?;
        } else {
            write!(f, "{key} {value} {}", self.range.unit)?;
        }
        write!(
            f,
            ": outside its plausible range {} ({})",
            self.range, self.range.why
        )
    }
}

impl std::error::Error for RangeError {}

/// A number as messages and the docs show it: in full below a billion,
/// very large and very small ones with an exponent (`1e300`, not three
/// hundred digits).
pub fn number(v: f64) -> String {
    let a = v.abs();
    if v.is_nan() {
        "NaN".into()
    } else if a.is_infinite() {
        if v > 0.0 { "inf" } else { "-inf" }.into()
    } else if a >= 1e9 || (a != 0.0 && a < 1e-3) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// Longest robot sensor, arena, training, experiment or fitted-profile
/// file: settings files are a few kilobytes.
pub const SETTINGS_FILE: Range = Range::closed(
    &["settings file size"],
    0.0,
    1024.0 * 1024.0,
    "bytes",
    "settings files (TOML, JSON) are a few kilobytes",
);

/// Longest policy blob file: the format's largest blob.
pub const POLICY_FILE: Range = Range::closed(
    &["policy file size"],
    0.0,
    shared::PolicyBlob::MAX_ENCODED_LEN as f64,
    "bytes",
    "the largest blob the format has",
);

/// Longest field image or photo file.
pub const IMAGE_FILE: Range = Range::closed(
    &["image file size"],
    0.0,
    64.0 * 1024.0 * 1024.0,
    "bytes",
    "a field image or a 50-megapixel photo is far smaller",
);

/// Longest recorded log or raw capture `host replay` reads.
pub const LOG_FILE: Range = Range::closed(
    &["log file size"],
    0.0,
    256.0 * 1024.0 * 1024.0,
    "bytes",
    "about a day of one robot's log at 50 frames a second",
);

/// Longest log `host view --log` plays: the page's document holds every
/// frame, some 8 bytes of it per byte of the log.
pub const VIEW_LOG_FILE: Range = Range::closed(
    &["viewed log file size"],
    0.0,
    64.0 * 1024.0 * 1024.0,
    "bytes",
    "about 6 hours of one robot's log; the page's document takes about 8 times the log (`host replay` reads any log up to the log file size)",
);

/// Longest checkpoint file.
pub const CHECKPOINT_FILE: Range = Range::closed(
    &["checkpoint file size"],
    0.0,
    256.0 * 1024.0 * 1024.0,
    "bytes",
    "a checkpoint of the largest world the ranges allow is a few megabytes",
);

/// Field image width and height.
pub const FIELD_IMAGE_SIDE: Range = Range::closed(
    &["field image width", "field image height"],
    1.0,
    4096.0,
    "pixels",
    "a field is read at most at a screen's resolution; the thesis' are 64 to 600 pixels",
);

/// Photo width and height (`host observe`).
pub const PHOTO_SIDE: Range = Range::closed(
    &["photo width", "photo height"],
    16.0,
    8192.0,
    "pixels",
    "a 50-megapixel camera's photo is 8688 x 5792",
);

/// Robots in a world.
pub const ROBOTS: Range = Range::closed(
    &["robots", "world.robots", "arena.robots"],
    1.0,
    1000.0,
    "",
    "at least one robot; the thesis' largest swarm is 32",
);

/// Pucks in a world.
pub const PUCKS: Range = Range::closed(
    &["pucks", "world.pucks", "arena.pucks"],
    1.0,
    100_000.0,
    "",
    "a formation needs pucks (Eval of none is 1); the thesis uses at most 250",
);

/// The arena's sides in robot radii.
pub const ARENA_IN_ROBOT_RADII: Range = Range::closed(
    &[
        "world.arena_width / world.robot_radius",
        "world.arena_height / world.robot_radius",
        "arena.screen_mm / arena.robot_radius_mm",
    ],
    2.0,
    400.0,
    "robot radii",
    "a robot must fit; the thesis' arena is 80 radii, the TV 25 (a robot radius in metres gives thousands)",
)
.above_min();

/// Millimetres per simulator unit.
pub const UNIT_MM: Range = Range::closed(
    &["world.unit_mm", "--mm-per-unit"],
    0.1,
    100.0,
    "mm",
    "a tenth of the robot's radius: 5 mm in the thesis, 6.5 mm for the Zumo",
);

/// The robot's radius in units.
pub const ROBOT_RADIUS_UNITS: Range = Range::closed(
    &["world.robot_radius"],
    0.1,
    1000.0,
    "units",
    "10 in every built-in arena (the unit is a tenth of it)",
);

/// A wedge skirt's tip distance from the robot's centre over the round
/// back's radius (`docs/robot-sensors.md`, "The skirt's outline").
pub const TIP_RADII: Range = Range::closed(
    &[
        "world.robot_shape.wedge.tip / world.robot_radius",
        "arena.robot_shape.wedge.tip_mm / arena.robot_radius_mm",
    ],
    1.0,
    3.0,
    "robot radii",
    "the tip lies beyond the round back; the thesis' wedge on the TV (tv75's) is 1.31 radii, and a longer needle is no skirt",
)
.above_min();

/// A puck's radius over a robot's.
pub const PUCK_OVER_ROBOT_RADIUS: Range = Range::closed(
    &["world.puck_radius / world.robot_radius"],
    0.1,
    10.0,
    "",
    "the thesis' pucks are as large as its robots",
);

/// A puck's mass over a robot's.
pub const PUCK_MASS_RATIO: Range = Range::closed(
    &["arena.puck_mass_ratio"],
    0.01,
    100.0,
    "",
    "the thesis' pucks weigh as much as its robots",
);

/// The forward speed in robot radii per step.
pub const FORWARD_SPEED_RADII: Range = Range::closed(
    &["world.forward_speed / world.robot_radius"],
    0.0,
    1.0,
    "robot radii per step",
    "a robot moving more than its radius in a step passes through what it should hit",
);

/// The forward speed in units (tenths of a robot radius) per step.
pub const FORWARD_SPEED: Range = Range::closed(
    &["arena.forward_speed", "forward_speed"],
    0.0,
    10.0,
    "units per step",
    "at most a robot radius per step; the thesis' is 2",
);

/// Velocity lost per step.
pub const DECELERATION: Range = Range::closed(
    &["physics.deceleration"],
    0.0,
    1.0,
    "of the velocity per step",
    "a fraction",
);

/// The physics' small lengths and speeds.
pub const PHYSICS_LENGTH: Range = Range::closed(
    &[
        "physics.stop_speed",
        "physics.overlap_threshold",
        "physics.wall_radius",
    ],
    0.0,
    100.0,
    "units",
    "0.001, 0.1 and 0 in the reference model; ten robot radii at most",
);

/// Angles of the disc sensors.
pub const DISC_ANGLE: Range = Range::closed(
    &["sensors.field_angle_deg", "sensors.*.angle_deg"],
    -180.0,
    180.0,
    "degrees",
    "a direction around the robot",
);

/// Distances of the disc sensors from the robot's centre.
pub const DISC_DISTANCE: Range = Range::closed(
    &["sensors.field_distance", "sensors.*.distance"],
    0.0,
    20.0,
    "robot radii",
    "the farthest reference disc is 7 radii out",
);

/// Radii of the disc sensors.
pub const DISC_RADIUS: Range = Range::closed(
    &["sensors.*.radius", "obstacle_discs.radius"],
    0.0,
    10.0,
    "robot radii",
    "the reference discs are 0.25 to 2 radii",
)
.above_min();

/// Field values, thresholds and Eval's weights.
pub const FRACTION: Range = Range::closed(
    &[
        "thresholds.outie",
        "thresholds.innie",
        "episode.success_eval",
        "episode.phi",
        "episode.nu",
        "learn.alpha",
        "learn.gamma",
        "learn.epsilon",
    ],
    0.0,
    1.0,
    "",
    "field values, Eval and the learning rates lie in [0, 1]",
);

/// Probabilities of the noise models.
pub const PROBABILITY: Range = Range::closed(
    &[
        "noise.block_miss",
        "noise.spurious_block",
        "noise.frame_drop",
        "world.actuation.drop_period",
    ],
    0.0,
    1.0,
    "",
    "a probability",
);

/// Relative spreads of the noise models.
pub const RELATIVE_NOISE: Range = Range::closed(
    &[
        "noise.rc_jitter",
        "noise.brightness",
        "world.actuation.period_jitter",
    ],
    0.0,
    0.15,
    "",
    "a standard deviation relative to the value; the defaults are 0.01 to 0.05, and 0.15 keeps the draws positive",
)
.below_max();

/// Each robot's wheel speed spread.
pub const SPEED_SPREAD: Range = Range::closed(
    &["world.actuation.speed_spread"],
    0.0,
    1.0,
    "",
    "wheel speeds 1 +- spread must stay positive",
)
.below_max();

/// Turning biases.
pub const TURN_BIAS: Range = Range::closed(
    &[
        "world.actuation.turn_bias",
        "world.actuation.robots[*].turn_bias",
    ],
    -0.5,
    0.5,
    "radians per step",
    "the default is 0.005; half a radian a step is a robot spinning",
);

/// A measured robot's wheel speed factor.
pub const WHEEL_SPEED_FACTOR: Range = Range::closed(
    &["world.actuation.robots[*].wheel_speed_factor"],
    0.2,
    5.0,
    "",
    "measured over intended speed; measured robots differ by about 10 %",
);

/// The noise multiplier.
pub const NOISE: Range = Range::closed(
    &["noise", "--also-noise"],
    0.0,
    5.0,
    "times the default noise",
    "0 none, 1 the default, 2 the robustness experiments' most",
);

/// Formation checks' interval.
pub const CHECK_INTERVAL: Range = Range::closed(
    &[
        "formation_check.every",
        "check_every",
        "episode.check_interval",
    ],
    1.0,
    1e7,
    "steps",
    "the thesis checks every 100 or 1,000 steps",
);

/// Steps without a formation before an episode is stuck.
pub const STUCK_LIMIT: Range = Range::closed(
    &["stuck_limit", "episode.stuck_limit", "arena.stuck_limit"],
    1.0,
    1e9,
    "steps",
    "the thesis' longest is 500,000",
);

/// Steps of a training run, a pre-training, an evaluation or a distillation.
pub const STEPS: Range = Range::closed(
    &[
        "steps",
        "pretrain.steps",
        "select.every",
        "select.steps",
        "distil_oc",
        "max_steps",
        "epsilon_decay",
        "--fitness-steps",
        "--validation-steps",
        "--window",
    ],
    1.0,
    1e10,
    "steps",
    "the thesis' runs are 5,000,000 steps; 10^10 take about a day",
);

/// Steps `host run` runs and `host render` runs before drawing.
pub const RUN_STEPS: Range = Range::closed(
    &["host run --steps", "host render --steps"],
    0.0,
    1e10,
    "steps",
    "200,000 by default, as a training run's range; 0 draws the first step",
);

/// Steps between the frames of an animation (`host render --gif`).
pub const FRAME_EVERY: Range = Range::closed(
    &["host render --every"],
    1.0,
    1e6,
    "steps",
    "--steps / 100 by default (100 frames), at least 1",
);

/// Steps between checkpoints.
pub const CHECKPOINT_EVERY: Range = Range::closed(
    &["checkpoint_every"],
    0.0,
    1e10,
    "steps",
    "0 for only at the end",
);

/// The Q-values' starting value.
pub const INITIAL_Q: Range = Range::closed(
    &["learn.initial_q"],
    -1e6,
    1e6,
    "",
    "rewards are at most 1 a step",
);

/// How close to the best Q-value an action ties with it.
pub const TIE_TOLERANCE: Range = Range::closed(
    &["learn.tie_tolerance", "--tie-tolerance"],
    0.0,
    1e6,
    "",
    "a difference of Q-values, which start within learn.initial_q's range; 0 ties only equal ones",
);

/// Angular speeds of the actions.
pub const ANGULAR_SPEED: Range = Range::closed(
    &["learn.actions", "actions"],
    -1.5,
    1.5,
    "radians per step",
    "the thesis' actions turn 0.15 and 0.3; 1.5 is a quarter turn a step",
);

/// The fraction of an experiment's step counts a run uses.
pub const SCALE: Range = Range::closed(
    &["--scale"],
    1e-6,
    10.0,
    "",
    "0.001 for a look, 1 for the thesis' counts",
);

/// Trials per arm of an experiment.
pub const TRIALS: Range = Range::closed(&["--trials"], 1.0, 1000.0, "", "the thesis runs 10");

/// Worker threads.
pub const THREADS: Range = Range::closed(
    &["--threads", "threads"],
    1.0,
    1024.0,
    "",
    "one per core (none, or `host search`'s 0, for one per core)",
);

/// Generations of the policy search (`host search`).
pub const GENERATIONS: Range = Range::closed(
    &["--generations"],
    1.0,
    100_000.0,
    "",
    "20 by default; each scores every candidate on every fitness world",
);

/// The minutes `host shape` may take.
pub const SHAPE_BUDGET: Range = Range::closed(
    &["host shape --budget-minutes"],
    0.1,
    10_080.0,
    "minutes",
    "20 by default, on two cores; a week at most",
);

/// Candidates per generation and elites of the policy search.
pub const CANDIDATES: Range = Range::closed(
    &["--population", "--elites"],
    1.0,
    1024.0,
    "",
    "16 and 4 by default; the population is at least 2 and holds the elites",
);

/// Worlds each candidate of the policy search is scored on.
pub const SEARCH_WORLDS: Range = Range::closed(
    &["--fitness-seeds", "--validation-seeds"],
    1.0,
    1000.0,
    "",
    "2 and 4 by default; the thesis' experiments run 10 trials",
);

/// The policy search's probabilities and shares.
pub const SEARCH_PROBABILITY: Range = Range::closed(
    &["--keep", "--rate", "--floor", "--hold-share"],
    0.0,
    1.0,
    "",
    "0.9, 0.5, 0.01 and 0 by default; --floor at most 1 / actions",
);

/// Rewards an n-step update sums.
pub const N_STEP: Range = Range::closed(
    &["n_step"],
    1.0,
    64.0,
    "rewards per update",
    "1, the thesis' one-step Q-learning, by default",
);

/// Innies among the robots.
pub const INNIES: Range = Range::closed(
    &["innies"],
    0.0,
    1000.0,
    "",
    "at most the robots; by default half of them on the annulus for OC, the robots of odd id for a role table",
);

/// `host`'s seeds: every 64-bit unsigned integer is one.
pub const SEED: Range = Range::closed(
    &["--seed", "--seeds"],
    0.0,
    u64::MAX as f64,
    "",
    "any unsigned 64-bit integer, 0 to 2^64 - 1",
);

/// Worlds of a Python vector environment.
pub const WORLDS: Range = Range::closed(
    &["num_worlds"],
    1.0,
    4096.0,
    "",
    "64 in the examples; each world holds its own robots and pucks",
);

/// Side of a rendered image.
pub const RENDER_SIZE: Range = Range::closed(
    &["--size", "size"],
    16.0,
    8192.0,
    "pixels",
    "800 by default",
);

/// The screen's visible size.
pub const SCREEN_MM: Range = Range::closed(
    &["arena.screen_mm"],
    100.0,
    10_000.0,
    "mm",
    "a 75\" TV is 1650 x 928 mm",
);

/// The panel's resolution.
pub const SCREEN_PX: Range = Range::closed(
    &["arena.screen_px"],
    16.0,
    8192.0,
    "pixels",
    "an 8K panel is 7680 x 4320",
);

/// Radii of robots and pucks on a screen.
pub const BODY_RADIUS_MM: Range = Range::closed(
    &["arena.robot_radius_mm", "arena.puck_radius_mm"],
    5.0,
    500.0,
    "mm",
    "the Zumo in its skirt is 65 mm",
);

/// Gammas of displays and of the light curve.
pub const GAMMA: Range = Range::closed(
    &["arena.display_gamma", "field.gamma"],
    0.5,
    4.0,
    "",
    "displays are 1.8 to 2.6; the light curve's is 2.2",
);

/// The share of a panel's brightness unevenness its robots see.
pub const UNEVENNESS: Range = Range::closed(
    &["arena.brightness_unevenness"],
    0.0,
    1.0,
    "",
    "1 for a panel as it comes; a flat-field correction (the shown image divided by the panel's measured gain) leaves less, never more",
);

/// The share of the robots' motion noise they show on a screen.
pub const MOTION_NOISE_SHARE: Range = Range::closed(
    &["arena.motion_noise"],
    0.0,
    1.0,
    "",
    "1 for open-loop motor commands, as the firmware drives them; wheel speeds held on the encoders would leave less, never more",
);

/// Points across and down of a panel's measured gain (`host field gain`'s
/// marks).
pub const GAIN_GRID_SIDE: Range = Range::closed(
    &["gain.columns", "gain.rows"],
    2.0,
    32.0,
    "",
    "bilinear needs two points a side; 32 x 32 marks is more than anyone measures by hand",
);

/// A panel's measured gain at a point, relative to the mean.
pub const PANEL_GAIN: Range = Range::closed(
    &["gain.gains"],
    0.0,
    10.0,
    "",
    "a panel's points differ by tens of per cent; a gain of 0 would show nothing",
)
.above_min();

/// Seconds the calibration sequence holds white and black.
pub const HOLD_S: Range = Range::closed(
    &["--hold"],
    0.5,
    20.0,
    "s",
    "each screen steady for 140 ms after the TV settles, both within the 60 s a robot waits",
);

/// Where a sensor sits on the robot.
pub const MOUNT_MM: Range = Range::closed(
    &[
        "field.mounts[*].forward_mm",
        "field.mounts[*].right_mm",
        "camera.forward_mm",
    ],
    -500.0,
    500.0,
    "mm",
    "on the robot or an outrigger: the longest swept is 130 mm",
);

/// Photo-transistor discharge times.
pub const DISCHARGE_US: Range = Range::closed(
    &["field.response[*].bright_us", "field.response[*].dark_us"],
    1.0,
    10_000.0,
    "us",
    "150 to 1820 us estimated; the firmware times out at 2000",
);

/// The firmware's timing latency.
pub const POLL_LATENCY_US: Range = Range::closed(
    &["field.poll_latency_us"],
    0.0,
    100.0,
    "us",
    "2.8 us measured in simavr",
);

/// The camera's and the markers' heights.
pub const HEIGHT_MM: Range = Range::closed(
    &[
        "camera.height_mm",
        "camera.puck_height_mm",
        "camera.robot_height_mm",
    ],
    0.0,
    1000.0,
    "mm",
    "the Pixy's lens is 80 mm up, pucks 30 mm tall",
)
.above_min();

/// The camera's tilt.
pub const TILT_DEG: Range = Range::closed(
    &["camera.tilt_deg"],
    -90.0,
    90.0,
    "degrees",
    "down is positive; with half the vertical field of view it stays within +-90",
);

/// The camera's fields of view.
pub const FOV_DEG: Range = Range::closed(
    &["camera.fov_h_deg", "camera.fov_v_deg"],
    0.0,
    180.0,
    "degrees",
    "the Pixy's lens is 75 x 47",
)
.above_min()
.below_max();

/// The camera's range.
pub const CAMERA_RANGE_MM: Range = Range::closed(
    &["camera.max_range_mm"],
    0.0,
    20_000.0,
    "mm",
    "1.25 m by default",
)
.above_min();

/// The camera's least blob.
pub const MIN_AREA_PX: Range = Range::closed(
    &["camera.min_area"],
    0.0,
    64_000.0,
    "pixels",
    "the Pixy's 20; its image is 320 x 200",
);

/// Distances in the camera's image.
pub const IMAGE_PX: Range = Range::closed(
    &["camera.merge_distance", "noise.block_jitter_px"],
    0.0,
    320.0,
    "pixels",
    "the image is 320 pixels wide",
);

/// Blocks per signature the camera sends.
pub const BLOCKS_PER_SIGNATURE: Range = Range::closed(
    &["camera.max_blocks_per_signature"],
    1.0,
    255.0,
    "",
    "2 by default; the Pixy's setting",
);

/// Frames in flight between the camera and the robot.
pub const LATENCY_FRAMES: Range = Range::closed(
    &["camera.latency_frames"],
    0.0,
    1.0,
    "frames",
    "the Pixy delivers a frame one period late; 0 for an ideal camera",
);

/// Wheel encoder counts per millimetre (`host replay`).
pub const COUNTS_PER_MM: Range = Range::closed(
    &["--counts-per-mm"],
    0.1,
    1000.0,
    "",
    "7.6 on the Zumo's 75:1 motors",
);

/// Track width (`host replay`).
pub const TRACK_MM: Range = Range::closed(&["--track-mm"], 10.0, 1000.0, "mm", "85 mm on the Zumo");

/// Frames `host monitor --frames` records before it stops.
pub const MONITOR_FRAMES: Range = Range::closed(
    &["--frames"],
    1.0,
    1e10,
    "frames",
    "a day at 50 frames a second is 4,320,000",
);

/// The robot's id (`host flash`).
pub const ROBOT_ID: Range = Range::closed(
    &["--robot-id"],
    0.0,
    255.0,
    "",
    "one byte in every log frame; 0 for none",
);

/// TCP ports of the servers (`host view`, `host display`).
pub const PORT: Range = Range::closed(&["--port"], 0.0, 65535.0, "", "0 for any free port");

/// Serial baud rates (`host monitor`).
pub const BAUD: Range = Range::closed(
    &["--baud"],
    300.0,
    4_000_000.0,
    "",
    "the firmware sends 115200",
);

/// The row a setting named `key` is checked against: the one `key` names
/// (its first key), if any.
pub fn row(key: &str) -> Option<&'static Range> {
    SECTIONS
        .iter()
        .flat_map(|(_, rows)| rows.iter().copied())
        .find(|r| r.key() == key)
}

/// The table: every range by section, in the order `docs/ranges.md` shows it.
pub const SECTIONS: &[(&str, &[&Range])] = &[
    (
        "World",
        &[
            &ROBOTS,
            &PUCKS,
            &ARENA_IN_ROBOT_RADII,
            &UNIT_MM,
            &ROBOT_RADIUS_UNITS,
            &TIP_RADII,
            &PUCK_OVER_ROBOT_RADIUS,
            &PUCK_MASS_RATIO,
            &FORWARD_SPEED_RADII,
            &FORWARD_SPEED,
            &DECELERATION,
            &PHYSICS_LENGTH,
            &FRACTION,
            &CHECK_INTERVAL,
            &STUCK_LIMIT,
        ],
    ),
    (
        "Screen arenas and the TV tools",
        &[
            &SCREEN_MM,
            &SCREEN_PX,
            &BODY_RADIUS_MM,
            &GAMMA,
            &UNEVENNESS,
            &MOTION_NOISE_SHARE,
            &GAIN_GRID_SIDE,
            &PANEL_GAIN,
            &HOLD_S,
            &FIELD_IMAGE_SIDE,
            &PHOTO_SIDE,
            &RENDER_SIZE,
        ],
    ),
    (
        "Sensors",
        &[
            &DISC_ANGLE,
            &DISC_DISTANCE,
            &DISC_RADIUS,
            &MOUNT_MM,
            &DISCHARGE_US,
            &POLL_LATENCY_US,
            &HEIGHT_MM,
            &TILT_DEG,
            &FOV_DEG,
            &CAMERA_RANGE_MM,
            &MIN_AREA_PX,
            &IMAGE_PX,
            &BLOCKS_PER_SIGNATURE,
            &LATENCY_FRAMES,
        ],
    ),
    (
        "Noise",
        &[
            &NOISE,
            &RELATIVE_NOISE,
            &PROBABILITY,
            &SPEED_SPREAD,
            &TURN_BIAS,
            &WHEEL_SPEED_FACTOR,
        ],
    ),
    (
        "Training, experiments and Python",
        &[
            &STEPS,
            &RUN_STEPS,
            &FRAME_EVERY,
            &CHECKPOINT_EVERY,
            &INITIAL_Q,
            &TIE_TOLERANCE,
            &ANGULAR_SPEED,
            &SCALE,
            &TRIALS,
            &THREADS,
            &WORLDS,
            &SEED,
            &N_STEP,
            &INNIES,
            &GENERATIONS,
            &SHAPE_BUDGET,
            &CANDIDATES,
            &SEARCH_WORLDS,
            &SEARCH_PROBABILITY,
        ],
    ),
    (
        "Robots and servers",
        &[
            &COUNTS_PER_MM,
            &TRACK_MM,
            &BAUD,
            &MONITOR_FRAMES,
            &ROBOT_ID,
            &PORT,
        ],
    ),
    (
        "Files, read no further than these sizes",
        &[
            &SETTINGS_FILE,
            &POLICY_FILE,
            &IMAGE_FILE,
            &LOG_FILE,
            &VIEW_LOG_FILE,
            &CHECKPOINT_FILE,
        ],
    ),
];

/// The table in markdown, as `docs/ranges.md` shows it: a heading per
/// section and a row per range (keys, range, why).
pub fn markdown() -> String {
    let mut out = String::new();
    for (section, ranges) in SECTIONS {
        out.push_str(&format!(
            "### {section}\n\n| keys | range | why |\n|---|---|---|\n"
        ));
        for r in *ranges {
            let keys: Vec<String> = r.keys.iter().map(|k| format!("`{k}`")).collect();
            out.push_str(&format!("| {} | {r} | {} |\n", keys.join(", "), r.why));
        }
        out.push('\n');
    }
    out
}

/// Reads the file at `path`, refusing one larger than `limit` allows
/// (read no further than that, so `/dev/zero` or a huge file costs
/// nothing): an `InvalidData` error that names the limit.
pub fn read_file(path: &Path, limit: &'static Range) -> std::io::Result<Vec<u8>> {
    let max = limit.max as u64;
    let file = std::fs::File::open(path)?;
    let mut bytes = Vec::new();
    file.take(max + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max {
        return Err(too_large(limit));
    }
    Ok(bytes)
}

/// The error of a file larger than `limit` allows (a reader that streams
/// a file reads no further than `limit.max + 1` bytes, then refuses it so).
pub fn too_large(limit: &'static Range) -> std::io::Error {
    std::io::Error::new(
        std::io::ErrorKind::InvalidData,
        format!(
            "larger than {} bytes, the most a {} is ({})",
            number(limit.max),
            limit.key().trim_end_matches(" size"),
            limit.why
        ),
    )
}

/// [`read_file`] as text.
pub fn read_text(path: &Path, limit: &'static Range) -> std::io::Result<String> {
    String::from_utf8(read_file(path, limit)?)
        .map_err(|_| std::io::Error::new(std::io::ErrorKind::InvalidData, "not UTF-8 text"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_refusal_names_the_key_the_value_and_the_range() {
        let e = PUCKS.check_count("pucks", 0).unwrap_err().to_string();
        assert_eq!(
            e,
            "pucks = 0: outside its plausible range [1, 100000] (a formation needs pucks (Eval of none is 1); the thesis uses at most 250)"
        );
        let e = MOUNT_MM
            .check_as("field.mounts[0].forward_mm", 1e300)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with(
                "field.mounts[0].forward_mm = 1e300: outside its plausible range [-500, 500] mm"
            ),
            "{e}"
        );
        let e = HOLD_S.check(1e9).unwrap_err().to_string();
        assert!(
            e.starts_with("--hold 1e9 s: outside its plausible range [0.5, 20] s"),
            "{e}"
        );
        assert!(DISC_RADIUS.check(0.0).is_err() && DISC_RADIUS.check(10.0).is_ok());
        assert!(RELATIVE_NOISE.check(0.15).is_err() && RELATIVE_NOISE.check(0.0).is_ok());
        assert!(GAMMA.check(f64::NAN).is_err() && GAMMA.check(f64::INFINITY).is_err());
        assert_eq!(number(1e-9), "1e-9");
        assert_eq!(number(0.065), "0.065");
        assert_eq!(number(2.0), "2");
    }

    #[test]
    fn every_range_is_a_real_interval_with_keys_of_its_own() {
        let mut seen = std::collections::BTreeSet::new();
        for (_, ranges) in SECTIONS {
            for r in *ranges {
                assert!(
                    r.min < r.max && r.min.is_finite() && r.max.is_finite(),
                    "{r:?}"
                );
                assert!(!r.why.is_empty(), "{r:?}");
                for k in r.keys {
                    assert!(seen.insert(*k), "{k} is in two rows");
                }
            }
        }
    }

    #[test]
    fn the_docs_show_this_table() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/ranges.md");
        let text = std::fs::read_to_string(&path).unwrap();
        let begin = "<!-- the table: sim/src/base/ranges.rs -->\n";
        let end = "<!-- end of the table -->";
        let start = text.find(begin).expect("the table's start marker") + begin.len();
        let stop = text.find(end).expect("the table's end marker");
        assert!(
            text[start..stop].trim() == markdown().trim(),
            "docs/ranges.md is not the table of sim/src/base/ranges.rs; between the markers it should read:\n{}",
            markdown()
        );
    }

    #[test]
    fn files_are_read_no_further_than_their_limit() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("big.policy");
        std::fs::write(&path, vec![7u8; POLICY_FILE.max as usize + 1]).unwrap();
        let e = read_file(&path, &POLICY_FILE).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::InvalidData);
        assert!(e.to_string().contains("the most a policy file is"), "{e}");
        std::fs::write(&path, [7u8; 10]).unwrap();
        assert_eq!(read_file(&path, &POLICY_FILE).unwrap(), [7u8; 10]);
        #[cfg(unix)]
        assert!(read_file(Path::new("/dev/zero"), &LOG_FILE).is_err());
    }
}
