//! The robot's three field sensors as the simulator models them:
//! photo-transistors under the front of the robot, read by RC discharge
//! timing exactly as the firmware reads them.
//!
//! Chain, per sensor (`docs/robot-sensors.md` gives the physics and how to
//! measure the parameters):
//! 1. the field value `v` the screen shows at the sensor's point (as the
//!    arena reads its field: the nearest cell in the thesis' arena,
//!    bilinear on a screen);
//! 2. the screen's light there, `L(v) = v^gamma` of full white (the light
//!    curve, [`shared::calibration::LIGHT_GAMMA`]);
//! 3. the discharge time: a photo-transistor's current is proportional to
//!    the light on it and the capacitor discharges at that current, so the
//!    time is inversely proportional to the light plus a dark current:
//!    `1/t = 1/t_dark + L(v) (1/t_bright - 1/t_dark)`, which is `t_bright`
//!    at `v = 1` and `t_dark` at `v = 0` (brighter is faster);
//! 4. whole Timer3 ticks, `floor((t + latency) / 4 us)`, capped at the
//!    2000 us timeout: the firmware polls the pins against the free-running
//!    timer and keeps the elapsed whole ticks; `latency` is its mean delay
//!    between a pin going low and the timer read that sees it, net of the
//!    time between the pins becoming inputs and the start read;
//! 5. the firmware's own calibration arithmetic ([`shared::FieldScales`])
//!    with the calibration the robot's procedure stores (its readings on
//!    the display's full-white and full-black screens, `docs/firmware.md`):
//!    each sensor's ticks at field 1.0 (bright) and 0.0 (dark).
//!
//! Steps 4 and 5 are the firmware's, so the simulator and the robot hash
//! identical inputs identically.

use crate::base::gain_grid::GainGrid;
use crate::base::noise::Stream;
use crate::base::ranges;
use crate::base::vec2::Vec2;
use crate::config::robot_shape::RobotShape;
use crate::config::validate::{check, ConfigError};
use crate::config::WorldConfig;
use crate::fields::{FieldLayout, ScalarField};
use crate::physics::outline::Outline;
use crate::sensors::robot_noise::RobotNoise;
use serde::{Deserialize, Serialize};
use shared::calibration::{LIGHT_GAMMA, RC_TICK_US, RC_TIMEOUT_TICKS};
use shared::{FieldCalibration, FieldScales, FieldValue, SensorRange};
use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_4};

/// A point on the robot, millimetres from its centre.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MountPoint {
    /// Ahead of the centre (negative: behind), mm.
    pub forward_mm: f64,
    /// To the right of the centre (negative: left), mm.
    pub right_mm: f64,
}

/// How one photo-transistor's discharge time depends on the light on it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhotoResponse {
    /// Discharge time over field value 1.0 (full projector brightness), us.
    pub bright_us: f64,
    /// Discharge time over field value 0.0 (projector black: ambient light
    /// and dark current only), us.
    pub dark_us: f64,
}

impl PhotoResponse {
    /// The discharge time in microseconds over a field value `v` in [0, 1]
    /// with projector gamma `gamma`.
    pub fn discharge_us(&self, v: f64, gamma: f64) -> f64 {
        discharge_at(self.rates(), light(v, gamma).unwrap_or(0.0))
    }

    /// The discharge rate in the dark, `1 / dark_us`, and what full white
    /// adds to it, `1 / bright_us - 1 / dark_us`.
    fn rates(&self) -> (f64, f64) {
        let (fast, slow) = (1.0 / self.bright_us, 1.0 / self.dark_us);
        (slow, fast - slow)
    }
}

/// The discharge time under `light` (relative to full white's) of a sensor of [`PhotoResponse::rates`]
/// `(slow, span)`: the inverse of its discharge rate.
fn discharge_at((slow, span): (f64, f64), light: f64) -> f64 {
    1.0 / (slow + light.max(0.0) * span)
}

/// The light `v.clamp(0, 1)^gamma` of full white at field value `v`, or
/// `None` for none (`v` at most 0, as off the screen's frame: a quarter
/// of the readings on `tv75`), skipping libm's `pow`, which gives a zero
/// there: under a zero of either sign a sensor discharges in its dark time
/// ([`discharge_at`]), whatever the gain on it.
fn light(v: f64, gamma: f64) -> Option<f64> {
    if v <= 0.0 {
        None
    } else {
        Some(v.clamp(0.0, 1.0).powf(gamma))
    }
}

/// The conditions of one reading with the sensor noise on: the screen's
/// brightness gains of the episode and the generator of the jitter.
pub(crate) struct PhotoNoise<'a> {
    /// The noise's settings.
    pub noise: &'a RobotNoise,
    /// The brightness gains ([`RobotNoise::brightness_grid`]).
    pub grid: &'a GainGrid,
    /// The arena's size, over which the gains lie.
    pub arena: Vec2,
    /// The generator of this reading's jitter.
    pub rng: &'a mut Stream,
}

/// Geometry and response of the three field sensors (left, mid, right).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PhotoSensorConfig {
    /// Where the left, mid and right sensors (DN1, DN3, DN5) sit; unset
    /// (the default), on the skirt's edge ([`PhotoSensorConfig::mounts_on`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mounts: Option<[MountPoint; 3]>,
    /// Each sensor's response.
    pub response: [PhotoResponse; 3],
    /// Projector gamma: light = value^gamma of full brightness.
    pub gamma: f64,
    /// The firmware's mean timing latency, us (see the module docs).
    pub poll_latency_us: f64,
    /// Ideal sensors, for ablations: the calibrated value is the field
    /// value shown at the point, exactly (no RC timing, no calibration).
    pub ideal: bool,
}

impl Default for PhotoSensorConfig {
    /// Photo-transistors on the skirt's edge ([`PhotoSensorConfig::mounts_on`]),
    /// wired to the front array's DN1, DN3 and DN5 pins: left and right 45
    /// degrees off the heading, mid straight ahead (chosen by the
    /// ablation and sweep in `docs/robot-sensors.md`: the front array's own
    /// spacing, 37.5 mm to each side, reads too little of the gradient);
    /// estimates, to be measured: discharge 150 to 170 us under full
    /// white and 1700 to 1820 us on black (the three sensors differ a
    /// little, as real ones do); the light curve's gamma,
    /// [`shared::calibration::LIGHT_GAMMA`]; the firmware's latency as
    /// measured in simavr, 2.8 us (`docs/robot-sensors.md`).
    fn default() -> PhotoSensorConfig {
        let response = |bright_us, dark_us| PhotoResponse { bright_us, dark_us };
        PhotoSensorConfig {
            mounts: None,
            response: [
                response(150.0, 1700.0),
                response(160.0, 1760.0),
                response(170.0, 1820.0),
            ],
            gamma: f64::from(LIGHT_GAMMA),
            poll_latency_us: 2.8,
            ideal: false,
        }
    }
}

/// `floor(us / tick)` capped at the timeout: the firmware's reading of a
/// discharge that takes `us` microseconds. The floor of `t` is at least a
/// whole `n` exactly when `t` is, and from 1 up it is `t`'s truncation, so
/// no rounding to a whole number is needed (NaN reads 0, as its floor does).
pub(crate) fn quantise_us(us: f64) -> u16 {
    let ticks = us / f64::from(RC_TICK_US);
    if ticks >= f64::from(RC_TIMEOUT_TICKS) {
        RC_TIMEOUT_TICKS
    } else if ticks >= 1.0 {
        ticks as u16
    } else {
        0
    }
}

const NAMES: [&str; 3] = ["left", "mid", "right"];

/// The round skirt's radius the photo-transistors sit on, mm: the least
/// circle around the Zumo's 98 x 86 mm chassis (`tv75`'s robots), in every
/// arena with disc robots.
pub const ROUND_SKIRT_MM: f64 = 65.0;

/// How far behind a wedge's tip the mid photo-transistor sits, mm: a
/// 3 mm part in a hole with foam around it, where the default wedge is
/// 12 mm wide.
pub const TIP_INSET_MM: f64 = 5.0;

impl PhotoSensorConfig {
    /// Where the sensors sit on the robots of `world`: the configured
    /// mounts, or on the skirt's edge. On a disc, the Zumo's round skirt
    /// ([`ROUND_SKIRT_MM`]): left and right 45 degrees off the heading, mid
    /// straight ahead. On a wedge, left and right where the outline meets
    /// the bearings of 45 degrees (the round back, or a face if the wedge
    /// reaches further back), mid [`TIP_INSET_MM`] behind the tip.
    pub fn mounts_on(&self, world: &WorldConfig) -> [MountPoint; 3] {
        if let Some(mounts) = self.mounts {
            return mounts;
        }
        let mount = |forward_mm, right_mm| MountPoint {
            forward_mm,
            right_mm,
        };
        let (side, mid) = match world.robot_shape {
            RobotShape::Disc => (ROUND_SKIRT_MM * FRAC_1_SQRT_2, ROUND_SKIRT_MM),
            RobotShape::Wedge { tip } => {
                let outline = Outline::new(world.robot_radius, tip);
                let to_mm = world.unit_mm;
                // The outline's distance from the centre along 45 degrees.
                let bearing = FRAC_PI_4;
                let tangent = (outline.radius() / outline.tip()).acos();
                let reach = if bearing >= tangent {
                    outline.radius()
                } else {
                    outline.radius() / (tangent - bearing).cos()
                };
                (
                    reach * to_mm * FRAC_1_SQRT_2,
                    outline.tip() * to_mm - TIP_INSET_MM,
                )
            }
        };
        [mount(side, -side), mount(mid, 0.0), mount(side, side)]
    }

    /// Checks every position, time and the gamma; each sensor's bright and
    /// dark times must differ by at least one tick, or no calibration exists.
    pub fn validate(&self) -> Result<(), ConfigError> {
        ranges::GAMMA.check_as("field.gamma", self.gamma)?;
        let latency = self.poll_latency_us;
        ranges::POLL_LATENCY_US.check(latency)?;
        for (i, name) in NAMES.iter().enumerate() {
            if let Some(m) = self.mounts.map(|m| m[i]) {
                ranges::MOUNT_MM.check_as(
                    &format!("field.mounts[{i}].forward_mm ({name})"),
                    m.forward_mm,
                )?;
                ranges::MOUNT_MM
                    .check_as(&format!("field.mounts[{i}].right_mm ({name})"), m.right_mm)?;
            }
            let r = self.response[i];
            ranges::DISCHARGE_US.check_as(
                &format!("field.response[{i}].bright_us ({name})"),
                r.bright_us,
            )?;
            ranges::DISCHARGE_US
                .check_as(&format!("field.response[{i}].dark_us ({name})"), r.dark_us)?;
            check(
                &format!("field.response[{i}].dark_us ({name})"),
                r.dark_us,
                quantise_us(r.dark_us + latency) > quantise_us(r.bright_us + latency),
                "must be at least one 4 us tick longer than bright_us",
            )?;
        }
        Ok(())
    }

    /// The calibration the robot stores from the display's white (1.0) and
    /// black (0.0) screens: per sensor, the firmware's readings of its
    /// bright and dark times.
    pub fn calibration(&self) -> FieldCalibration {
        let ticks = |us: f64| quantise_us(us + self.poll_latency_us);
        FieldCalibration {
            ranges: self.response.map(|r| SensorRange {
                bright: ticks(r.bright_us),
                dark: ticks(r.dark_us),
            }),
        }
    }
}

/// What the three field sensors measure in one control period.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct PhotoReading {
    /// Discharge times, us (the pins' behaviour, before the firmware's
    /// latency and quantisation).
    pub discharge_us: [f64; 3],
    /// The firmware's raw readings: whole Timer3 ticks, capped at the timeout.
    pub ticks: [u16; 3],
    /// The calibrated values: the firmware's arithmetic on `ticks` (or,
    /// with ideal sensors, the field values shown).
    pub values: [FieldValue; 3],
}

/// The three sensors of a robot, ready to read.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct PhotoSensors {
    /// Left, mid, right points in the robot's frame (x forward, y right), units.
    points: [Vec2; 3],
    response: [PhotoResponse; 3],
    /// Each sensor's [`PhotoResponse::rates`], computed once.
    rates: [(f64, f64); 3],
    gamma: f64,
    latency_us: f64,
    ideal: bool,
    calibration: FieldCalibration,
    scales: FieldScales,
    /// Each sensor's calibrated value of every reading a discharge can
    /// give (`0..=RC_TIMEOUT_TICKS`): `scales`' arithmetic done once, so
    /// that a reading is one load.
    values_of_ticks: Box<[[FieldValue; READINGS]; 3]>,
}

/// The readings a discharge can give: whole ticks up to the timeout.
const READINGS: usize = RC_TIMEOUT_TICKS as usize + 1;

impl PhotoSensors {
    /// The sensors of `config` on the robots of `world`.
    pub fn new(config: &PhotoSensorConfig, world: &WorldConfig) -> PhotoSensors {
        let calibration = config.calibration();
        let scales = calibration.scales();
        let unit_mm = world.unit_mm;
        PhotoSensors {
            points: config
                .mounts_on(world)
                .map(|m| Vec2::new(m.forward_mm / unit_mm, m.right_mm / unit_mm)),
            response: config.response,
            rates: config.response.map(|r| r.rates()),
            gamma: config.gamma,
            latency_us: config.poll_latency_us,
            ideal: config.ideal,
            calibration,
            scales,
            values_of_ticks: Box::new(std::array::from_fn(|i| {
                std::array::from_fn(|t| scales.0[i].value(t as u16))
            })),
        }
    }

    /// The calibration the robot stores (and the firmware applies).
    pub fn calibration(&self) -> FieldCalibration {
        self.calibration
    }

    /// Calibrated values of raw readings, with the firmware's arithmetic.
    pub fn values(&self, ticks: &[u16; 3]) -> [FieldValue; 3] {
        self.scales.values(ticks)
    }

    /// The sensor points in the robot's frame (x forward, y right), units.
    pub fn points(&self) -> &[Vec2; 3] {
        &self.points
    }

    /// The reading of a robot at `pos` facing `direction` (unit vector),
    /// with the sensor noise if given.
    pub fn read(
        &self,
        pos: Vec2,
        direction: Vec2,
        field: &ScalarField,
        layout: &FieldLayout,
        mut noise: Option<PhotoNoise<'_>>,
    ) -> PhotoReading {
        let mut r = PhotoReading::default();
        let mut shown = [0.0; 3];
        #[allow(
            clippy::needless_range_loop,
            reason = "sensor i of four arrays: an index reads plainer than a zip"
        )]
        for i in 0..3 {
            let point = pos + self.points[i].rotated(direction);
            shown[i] = field.shown(point, layout);
            r.discharge_us[i] = match noise.as_mut() {
                None => self.response[i].discharge_us(shown[i], self.gamma),
                Some(n) => {
                    let light =
                        light(shown[i], self.gamma).map_or(0.0, |l| l * n.grid.at(point, n.arena));
                    n.noise
                        .jitter_discharge(discharge_at(self.rates[i], light), n.rng)
                }
            };
            r.ticks[i] = quantise_us(r.discharge_us[i] + self.latency_us);
        }
        r.values = if self.ideal {
            shown.map(|v| FieldValue::from_f32(v as f32))
        } else {
            // Ticks are at most the timeout (`quantise_us`).
            std::array::from_fn(|i| self.values_of_ticks[i][usize::from(r.ticks[i])])
        };
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fields::{FieldFrame, FieldSampling};

    /// A 100 x 100 arena, nearest cell.
    const SQUARE_100: FieldLayout = FieldLayout {
        frame: FieldFrame::whole(100.0, 100.0),
        sampling: FieldSampling::Nearest,
    };

    #[test]
    fn brighter_discharges_faster_between_the_calibrated_ends() {
        let c = PhotoSensorConfig::default();
        let r = c.response[1];
        assert!((r.discharge_us(1.0, c.gamma) - 160.0).abs() < 1e-9);
        assert!((r.discharge_us(0.0, c.gamma) - 1760.0).abs() < 1e-9);
        let mut last = f64::INFINITY;
        for k in 0..=100 {
            let t = r.discharge_us(f64::from(k) / 100.0, c.gamma);
            assert!(t < last, "not faster at {k}%");
            last = t;
        }
        // Inverse in the light: half the light of full brightness (above the
        // dark current) is less than twice the bright time.
        let half_light = 0.5f64.powf(1.0 / c.gamma);
        assert!(r.discharge_us(half_light, c.gamma) < 2.0 * 160.0 + 1.0);
    }

    #[test]
    fn quantisation_floors_to_ticks_and_caps_at_the_timeout() {
        assert_eq!(quantise_us(0.0), 0);
        assert_eq!(quantise_us(3.99), 0);
        assert_eq!(quantise_us(4.0), 1);
        assert_eq!(quantise_us(1759.9), 439);
        assert_eq!(quantise_us(1999.0), 499);
        assert_eq!(quantise_us(2000.0), RC_TIMEOUT_TICKS);
        assert_eq!(quantise_us(1e9), RC_TIMEOUT_TICKS);
        assert_eq!(quantise_us(-5.0), 0);
        assert_eq!(quantise_us(f64::NAN), 0);
        // As the floor of the ticks, rounded to a whole number, gives them.
        for k in 0..=20_000 {
            let us = f64::from(k) * 0.1003;
            let floor = crate::base::rounding::floor(us / f64::from(RC_TICK_US));
            let capped = floor.clamp(0.0, f64::from(RC_TIMEOUT_TICKS)) as u16;
            assert_eq!(quantise_us(us), capped, "{us} us");
        }
    }

    #[test]
    fn full_and_no_light_read_one_and_zero_through_the_calibration() {
        let config = PhotoSensorConfig::default();
        let cal = config.calibration();
        // (150 + 2.8) / 4 and (1700 + 2.8) / 4, floored.
        assert_eq!(
            cal.ranges[0],
            SensorRange {
                bright: 38,
                dark: 425
            }
        );
        let sensors = PhotoSensors::new(&config, &WorldConfig::default());
        let bright = ScalarField::new(1, 1, vec![1.0]).unwrap();
        let dark = ScalarField::new(1, 1, vec![0.0]).unwrap();
        // One cell over the whole arena: every point inside reads it.
        let at = Vec2::new(20.0, 20.0);
        let r = sensors.read(at, Vec2::new(1.0, 0.0), &bright, &SQUARE_100, None);
        assert_eq!(sensors.values(&r.ticks), [FieldValue::ONE; 3]);
        assert_eq!(r.ticks, cal.ranges.map(|c| c.bright));
        let r = sensors.read(at, Vec2::new(1.0, 0.0), &dark, &SQUARE_100, None);
        assert_eq!(sensors.values(&r.ticks), [FieldValue::ZERO; 3]);
        assert_eq!(r.ticks, cal.ranges.map(|c| c.dark));
    }

    #[test]
    fn a_reading_s_tabulated_value_is_the_firmware_arithmetic_on_its_ticks() {
        let mut config = PhotoSensorConfig::default();
        for (bright_us, dark_us) in [(150.0, 1700.0), (40.0, 1990.0), (900.0, 2400.0)] {
            config.response[1] = PhotoResponse { bright_us, dark_us };
            let sensors = PhotoSensors::new(&config, &WorldConfig::default());
            for t in 0..=RC_TIMEOUT_TICKS {
                let ticks = [t; 3];
                let tabulated = std::array::from_fn(|i| sensors.values_of_ticks[i][usize::from(t)]);
                assert_eq!(tabulated, sensors.values(&ticks), "{t} ticks");
            }
        }
    }

    #[test]
    fn sensors_sit_where_configured_and_turn_with_the_robot() {
        // A field bright in its left column only (2 x 1 cells over 100 units).
        let field = ScalarField::new(2, 1, vec![1.0, 0.0]).unwrap();
        let sensors = PhotoSensors::new(&PhotoSensorConfig::default(), &WorldConfig::default());
        // Facing down the screen (+y): the robot's right is -x, so its right
        // sensor is over the bright column at x < 25 (cell 0 by rounding).
        let r = sensors.read(
            Vec2::new(24.0, 20.0),
            Vec2::new(0.0, 1.0),
            &field,
            &SQUARE_100,
            None,
        );
        let values = sensors.values(&r.ticks);
        assert_eq!((values[0], values[2]), (FieldValue::ZERO, FieldValue::ONE));
    }

    #[test]
    fn bad_settings_are_named() {
        let mut c = PhotoSensorConfig::default();
        c.response[2].dark_us = c.response[2].bright_us + 1.0;
        let e = c.validate().unwrap_err().to_string();
        assert!(e.contains("field.response[2].dark_us (right)"), "{e}");
        let c = PhotoSensorConfig {
            gamma: 0.0,
            ..PhotoSensorConfig::default()
        };
        assert!(c
            .validate()
            .unwrap_err()
            .to_string()
            .contains("field.gamma"));
        assert!(PhotoSensorConfig::default().validate().is_ok());
    }
}
