//! The senses' noise files of the T's noise experiment
//! (`experiments/robot-senses/noise-*.json`, used by
//! `experiments/t-noise.toml`) are the simulator's default noise with the
//! models their names double, so the experiment measures what it says.

use sim::sensors::robot::RobotSensorConfig;
use sim::sensors::robot_noise::RobotNoise;
use std::path::Path;

fn noise_of(file: &str) -> RobotNoise {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../experiments/robot-senses")
        .join(file);
    let text = std::fs::read_to_string(&path).expect("a noise file of the t-noise experiment");
    let config: RobotSensorConfig = serde_json::from_str(&text).expect("a robot sensor config");
    assert_eq!(
        RobotSensorConfig {
            noise: RobotNoise::NONE,
            ..config.clone()
        },
        RobotSensorConfig::default(),
        "{file} changes more than the noise"
    );
    config.noise
}

#[test]
fn each_noise_file_is_the_default_noise_with_the_models_its_name_doubles() {
    let one = RobotNoise::randomised();
    let two = one.scaled(2.0);
    assert_eq!(noise_of("noise-default.json"), one);
    assert_eq!(noise_of("noise-2x.json"), two);
    assert_eq!(
        noise_of("noise-default-brightness-2x.json"),
        RobotNoise {
            brightness: two.brightness,
            ..one.clone()
        }
    );
    assert_eq!(
        noise_of("noise-default-camera-2x.json"),
        RobotNoise {
            block_jitter_px: two.block_jitter_px,
            block_miss: two.block_miss,
            spurious_block: two.spurious_block,
            frame_drop: two.frame_drop,
            ..one.clone()
        }
    );
    assert_eq!(
        noise_of("noise-default-rc-2x.json"),
        RobotNoise {
            rc_jitter: two.rc_jitter,
            ..one.clone()
        }
    );
    assert_eq!(
        noise_of("noise-2x-brightness-default.json"),
        RobotNoise {
            brightness: one.brightness,
            ..two
        }
    );
}
