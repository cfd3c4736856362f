//! What a policy was trained for, as its blob records it
//! ([`shared::TrainedFor`]), and the word a run says when it runs a policy
//! under another sensor model or in another arena.

use crate::scenario::arena_choice::ArenaChoice;
use crate::scenario::sensor_choice::SensorChoice;
use shared::blob::name_prefix;
use shared::TrainedFor;

/// The sensor model's name in a blob: `disc`, `disc-thesis`, `robot` (with
/// or without a settings file: the same model) or `mix:` and the three.
pub fn sensors_label(sensors: &SensorChoice) -> String {
    match sensors {
        SensorChoice::Disc => "disc".into(),
        SensorChoice::DiscThesis => "disc-thesis".into(),
        SensorChoice::Robot(_) => "robot".into(),
        SensorChoice::Mixed(parts) => {
            let names: Vec<String> = parts.iter().map(sensors_label).collect();
            format!("mix:{}", names.join("+"))
        }
    }
}

/// The arena's name in a blob: `thesis`, a built-in arena's name, or an
/// arena file's name (without its folder).
pub fn arena_label(arena: &ArenaChoice) -> String {
    match arena {
        ArenaChoice::File(path) => path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into(),
        ),
        other => other.to_string(),
    }
}

/// What a run of `sensors` in `arena` trains for, each name cut to
/// [`shared::blob::MAX_NAME_LEN`] bytes.
pub fn trained_for(sensors: &SensorChoice, arena: &ArenaChoice) -> TrainedFor {
    let (sensors, arena) = (sensors_label(sensors), arena_label(arena));
    TrainedFor::new(name_prefix(&sensors), name_prefix(&arena)).unwrap_or_default()
}

/// The warning for running a policy trained for `policy` with `run`, or
/// `None` when they agree (or the blob does not say, format version 1).
pub fn mismatch(policy: Option<&TrainedFor>, run: &TrainedFor) -> Option<String> {
    let policy = policy?;
    let mut differ = Vec::new();
    if policy.sensors != run.sensors {
        differ.push(format!(
            "sensor model {} (this run: {})",
            policy.sensors.escape_debug(),
            run.sensors
        ));
    }
    if policy.arena != run.arena {
        differ.push(format!(
            "arena {} (this run: {})",
            policy.arena.escape_debug(),
            run.arena
        ));
    }
    (!differ.is_empty()).then(|| {
        format!(
            "the policy was trained for {}; its states mean what that sensor model reported there, so it may act poorly here",
            differ.join(" and ")
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    #[test]
    fn labels_name_the_model_and_arena_not_their_files() {
        let robot_file = SensorChoice::Robot(Some(PathBuf::from("x/fit.json")));
        let file = ArenaChoice::File(PathBuf::from("experiments/arenas/small.toml"));
        let t = trained_for(&robot_file, &file);
        assert_eq!(
            (t.sensors.as_str(), t.arena.as_str()),
            ("robot", "small.toml")
        );
        let t = trained_for(&SensorChoice::Disc, &ArenaChoice::Thesis);
        assert_eq!((t.sensors.as_str(), t.arena.as_str()), ("disc", "thesis"));
        let mix = SensorChoice::Mixed(Box::new([
            SensorChoice::DiscThesis,
            SensorChoice::DiscThesis,
            SensorChoice::DiscThesis,
        ]));
        assert_eq!(trained_for(&mix, &ArenaChoice::Thesis).sensors.len(), 32);
    }

    #[test]
    fn a_mismatch_names_what_differs_and_agreement_says_nothing() {
        let robot_tv = trained_for(
            &SensorChoice::Robot(None),
            &ArenaChoice::Named("tv75".into()),
        );
        let disc = trained_for(&SensorChoice::Disc, &ArenaChoice::Named("tv75".into()));
        let text = mismatch(Some(&robot_tv), &disc).unwrap();
        assert!(
            text.contains("sensor model robot (this run: disc)"),
            "{text}"
        );
        assert!(!text.contains("arena"), "{text}");
        assert_eq!(mismatch(Some(&robot_tv), &robot_tv), None);
        assert_eq!(mismatch(None, &disc), None);
        let thesis = trained_for(&SensorChoice::Robot(None), &ArenaChoice::Thesis);
        assert!(mismatch(Some(&robot_tv), &thesis)
            .unwrap()
            .contains("arena tv75 (this run: thesis)"));
    }
}
