//! `host observe` on photos of known scenes: the simulator draws a world
//! top-down (`sim::render::draw_world`), a perspective camera here turns
//! it into a photo of the TV lying on a floor, and the detected pucks,
//! Eval and the verdict are checked against the world's own. One photo is
//! made photograph-like: uneven light, a colour cast, a glare spot, blur,
//! sensor noise and JPEG compression.

use host::observe::homography::Homography;
use image::{Rgb, RgbImage};
use rand::{RngExt, SeedableRng};
use sim::base::vec2::Vec2;
use sim::fields::source::FieldSource;
use sim::fields::ScalarField;
use sim::scenario::arena::ArenaSpec;
use sim::scenario::{Arena, Scenario};
use sim::world::World;
use sim::{base::rng::SimRng, config::SimConfig, physics::body::RobotKind};
use std::path::Path;
use std::process::Command;

const HOST: &str = env!("CARGO_BIN_EXE_host");

/// Top-down pixels per unit of the scene the camera sees.
const SCENE_SCALE: f64 = 6.0;

/// The photo's size.
const PHOTO: (u32, u32) = (1600, 1200);

/// The TV seen from above and a little to the side: the screen's corners
/// in the photo (top-left, top-right, bottom-right, bottom-left).
const MILD: [[f64; 2]; 4] = [
    [170.0, 250.0],
    [1450.0, 215.0],
    [1500.0, 960.0],
    [120.0, 1000.0],
];

/// A steeper view: the far edge shorter, the whole rotated a little.
const STEEP: [[f64; 2]; 4] = [
    [330.0, 200.0],
    [1270.0, 250.0],
    [1530.0, 1060.0],
    [60.0, 960.0],
];

fn tv75_config(field: &ScalarField) -> SimConfig {
    let scenario = Scenario {
        arena: Arena::Screen(Box::new(ArenaSpec::tv75())),
        ..Scenario::default()
    };
    scenario.config(field)
}

fn annulus() -> ScalarField {
    ArenaSpec::tv75().load_field(&FieldSource::Annulus).unwrap()
}

/// The camera: each photo pixel shows the top-down scene where the
/// perspective map sends it, the screen's black bezel (20 mm) around it and
/// a wooden floor beyond.
fn photograph(scene: &RgbImage, corners: &[[f64; 2]; 4]) -> RgbImage {
    let size = ArenaSpec::tv75().size();
    let screen = [[0.0, 0.0], [size.x, 0.0], [size.x, size.y], [0.0, size.y]];
    let to_screen = Homography::from_points(corners, &screen).unwrap();
    let bezel = 20.0 / ArenaSpec::tv75().unit_mm();
    RgbImage::from_fn(PHOTO.0, PHOTO.1, |x, y| {
        let Some([u, v]) = to_screen.apply([f64::from(x) + 0.5, f64::from(y) + 0.5]) else {
            return Rgb([120, 90, 60]);
        };
        if (0.0..size.x).contains(&u) && (0.0..size.y).contains(&v) {
            host::observe::sample(scene, [u * SCENE_SCALE, v * SCENE_SCALE])
        } else if (-bezel..size.x + bezel).contains(&u) && (-bezel..size.y + bezel).contains(&v) {
            Rgb([18, 18, 20])
        } else {
            Rgb([120, 90, 60])
        }
    })
}

/// Makes a photo photograph-like: light falling off to the left and to
/// the corners, a warm cast, a glare spot, optical blur and sensor noise.
fn weather(photo: &RgbImage, glare: [f64; 2], seed: u64) -> RgbImage {
    let blurred = image::imageops::blur(photo, 1.2);
    let mut rng = SimRng::seed_from_u64(seed);
    let (w, h) = (f64::from(PHOTO.0), f64::from(PHOTO.1));
    RgbImage::from_fn(PHOTO.0, PHOTO.1, |x, y| {
        let (fx, fy) = (f64::from(x), f64::from(y));
        let r2 = ((fx - w / 2.0) / w).powi(2) + ((fy - h / 2.0) / h).powi(2);
        let light = (0.55 + 0.55 * fx / w) * (1.0 - 0.8 * r2);
        let spot = 90.0
            * (-((fx - glare[0]).powi(2) + (fy - glare[1]).powi(2)) / (2.0 * 60.0f64.powi(2)))
                .exp();
        let p = blurred.get_pixel(x, y).0;
        Rgb(std::array::from_fn(|k| {
            let cast = [1.06, 1.0, 0.86][k];
            // Box-Muller: one standard normal sample.
            let (a, b): (f64, f64) = (rng.random_range(f64::EPSILON..1.0), rng.random());
            let noise = 7.0 * (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos();
            (f64::from(p[k]) * light * cast + spot + noise)
                .round()
                .clamp(0.0, 255.0) as u8
        }))
    })
}

/// Twelve pucks on the annulus' contour of value 0.7 (its band is 0.6 to
/// 0.8): a formed shape, with the robots outside it.
fn formed_ring(field: &ScalarField, config: &SimConfig) -> World {
    let layout = config.world.field_layout();
    let size = config.world.arena();
    let centre = (0..(size.x as usize))
        .flat_map(|x| {
            (0..(size.y as usize)).map(move |y| Vec2::new(x as f64 + 0.5, y as f64 + 0.5))
        })
        .max_by(|a, b| {
            field
                .evaluate(*a, &layout)
                .total_cmp(&field.evaluate(*b, &layout))
        })
        .unwrap();
    let pucks: Vec<Vec2> = (0..12)
        .map(|k| {
            let direction = Vec2::from_angle(f64::from(k) * std::f64::consts::TAU / 12.0 + 0.1);
            // The field falls along every ray: bisect for 0.7.
            let (mut near, mut far) = (0.0, size.y);
            for _ in 0..40 {
                let mid = (near + far) / 2.0;
                if field.evaluate(centre + direction * mid, &layout) > 0.7 {
                    near = mid;
                } else {
                    far = mid;
                }
            }
            centre + direction * near
        })
        .collect();
    let robots: Vec<(Vec2, f64, RobotKind)> = [
        [20.0, 30.0],
        [20.0, 110.0],
        [235.0, 30.0],
        [235.0, 110.0],
        [55.0, 125.0],
    ]
    .map(|[x, y]| (Vec2::new(x, y), 0.5, RobotKind::Outie))
    .to_vec();
    World::scene(config, &robots, &pucks, 1)
}

/// The world of orbital construction on the TV after 2,000 steps, or
/// after the first step from there at which no two pucks overlap: a new
/// episode places its bodies overlapping and physics pushes them apart over
/// some steps, and a photo shows two pucks in one place as one.
fn mid_run() -> World {
    let scenario = Scenario {
        arena: Arena::Screen(Box::new(ArenaSpec::tv75())),
        seed: 7,
        ..Scenario::default()
    };
    let (mut sim, mut controller) = scenario.build().unwrap();
    sim.run(&mut *controller, 2000);
    let apart = |w: &World| {
        let p = w.pucks();
        let reach = 2.0 * w.config().puck_radius - 0.5;
        (0..p.len()).all(|i| (i + 1..p.len()).all(|j| (p[i].pos - p[j].pos).length() > reach))
    };
    for _ in 0..2000 {
        if apart(sim.world()) {
            return sim.world().clone();
        }
        sim.run(&mut *controller, 1);
    }
    panic!("the pucks kept overlapping for 2,000 steps");
}

/// Four pucks in a touching row, three touching in a triangle, five apart.
fn clusters(config: &SimConfig) -> World {
    let mut pucks: Vec<Vec2> = (0..4)
        .map(|k| Vec2::new(40.0 + 20.0 * f64::from(k), 30.0))
        .collect();
    let third = Vec2::new(170.0, 60.0);
    pucks.extend([
        third,
        third + Vec2::new(20.0, 0.0),
        third + Vec2::new(10.0, 17.4),
    ]);
    pucks.extend(
        [
            [30.0, 110.0],
            [90.0, 80.0],
            [140.0, 120.0],
            [210.0, 25.0],
            [230.0, 115.0],
        ]
        .map(|[x, y]| Vec2::new(x, y)),
    );
    World::scene(
        config,
        &[(Vec2::new(125.0, 70.0), 1.0, RobotKind::Outie)],
        &pucks,
        1,
    )
}

/// What `host observe` reported.
struct Report {
    pucks: Vec<Vec2>,
    eval: f64,
    formed: bool,
}

fn observe(photo: &Path, corners: &[[f64; 2]; 4], picture: Option<&Path>) -> Report {
    let corners = corners
        .iter()
        .flat_map(|c| c.iter().map(|v| v.to_string()))
        .collect::<Vec<_>>()
        .join(",");
    let mut command = Command::new(HOST);
    command.args([
        "observe",
        "--arena",
        "tv75",
        "--field",
        "annulus",
        "--json",
        "--corners",
        &corners,
        "--photo",
    ]);
    command.arg(photo);
    if let Some(path) = picture {
        command.arg("--picture").arg(path);
    }
    let out = command.output().unwrap();
    assert!(
        out.status.success(),
        "host observe: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let pucks = v["pucks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| Vec2::new(p["x"].as_f64().unwrap(), p["y"].as_f64().unwrap()));
    Report {
        pucks: pucks.collect(),
        eval: v["eval"].as_f64().unwrap(),
        formed: v["formed"].as_bool().unwrap(),
    }
}

/// Each true puck's distance to the detected puck matched to it (nearest
/// first, one to one); fails if the counts differ.
fn match_errors(truth: &World, found: &[Vec2]) -> Vec<f64> {
    assert_eq!(found.len(), truth.pucks().len(), "pucks found: {found:?}");
    let mut pairs: Vec<(f64, usize, usize)> = truth
        .pucks()
        .iter()
        .enumerate()
        .flat_map(|(i, p)| {
            found
                .iter()
                .enumerate()
                .map(move |(j, q)| ((p.pos - *q).length(), i, j))
        })
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (mut used_true, mut used_found, mut errors) = (
        vec![false; found.len()],
        vec![false; found.len()],
        Vec::new(),
    );
    for (d, i, j) in pairs {
        if !used_true[i] && !used_found[j] {
            used_true[i] = true;
            used_found[j] = true;
            errors.push(d);
        }
    }
    errors
}

fn check(world: &World, field: &ScalarField, config: &SimConfig, report: &Report, tolerance: f64) {
    let errors = match_errors(world, &report.pucks);
    let worst = errors.iter().cloned().fold(0.0, f64::max);
    assert!(
        worst < tolerance,
        "a puck found {worst:.2} units from where it is: {errors:.2?}"
    );
    let truth = sim::episodes::eval::eval(world, field, &config.thresholds);
    assert!(
        (report.eval - truth).abs() < 0.005,
        "Eval {} against the world's {truth}",
        report.eval
    );
    assert_eq!(
        report.formed,
        truth > config.episode.success_eval,
        "Eval {} (world {truth})",
        report.eval
    );
}

fn save(img: &RgbImage, path: &Path) {
    img.save(path).unwrap();
}

#[test]
fn pucks_in_a_rendered_perspective_photo_are_found_where_they_are() {
    let dir = tempfile::tempdir().unwrap();
    let field = annulus();
    let config = tv75_config(&field);
    for (name, world, corners) in [
        ("mid-run", mid_run(), MILD),
        ("clusters", clusters(&config), MILD),
        ("ring", formed_ring(&field, &config), STEEP),
    ] {
        let scene = sim::render::draw_world(
            &world,
            &field,
            (config.world.arena().x * SCENE_SCALE) as u32,
        );
        let photo = dir.path().join(format!("{name}.png"));
        save(&photograph(&scene, &corners), &photo);
        let report = observe(&photo, &corners, None);
        // 0.3 units: 2 mm.
        check(&world, &field, &config, &report, 0.3);
        if name == "ring" {
            assert!(report.formed, "the ring is formed");
        }
    }
}

#[test]
fn a_photograph_like_jpeg_with_uneven_light_and_noise_still_shows_the_formed_ring() {
    let dir = tempfile::tempdir().unwrap();
    let field = annulus();
    let config = tv75_config(&field);
    let world = formed_ring(&field, &config);
    let scene = sim::render::draw_world(
        &world,
        &field,
        (config.world.arena().x * SCENE_SCALE) as u32,
    );
    // The glare spot half over a puck.
    let size = config.world.arena();
    let to_photo = Homography::from_points(
        &[[0.0, 0.0], [size.x, 0.0], [size.x, size.y], [0.0, size.y]],
        &STEEP,
    )
    .unwrap();
    let [gx, gy] = to_photo
        .apply([world.pucks()[2].pos.x, world.pucks()[2].pos.y])
        .unwrap();
    let photo = weather(&photograph(&scene, &STEEP), [gx + 45.0, gy - 20.0], 3);
    let path = dir.path().join("photo.jpg");
    let mut bytes = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut bytes, 80)
        .encode_image(&photo)
        .unwrap();
    std::fs::write(&path, bytes).unwrap();
    let picture = dir.path().join("picture.png");
    let report = observe(&path, &STEEP, Some(&picture));

    // 0.5 units: 3 mm.
    check(&world, &field, &config, &report, 0.5);
    assert!(report.formed && report.eval > 0.94, "Eval {}", report.eval);
    let picture = image::open(&picture).unwrap();
    assert!(
        picture.width() > 500 && picture.height() > picture.width() / 2,
        "{:?}",
        (picture.width(), picture.height())
    );
}

#[test]
fn bad_corners_colours_and_photos_are_refused_naming_the_input() {
    let dir = tempfile::tempdir().unwrap();
    let photo = dir.path().join("floor.png");
    save(
        &RgbImage::from_pixel(400, 300, Rgb([100, 100, 100])),
        &photo,
    );
    let photo = photo.to_str().unwrap();
    let fails = |args: &[&str]| {
        let out = Command::new(HOST)
            .args(["observe", "--photo"])
            .args(args)
            .output()
            .unwrap();
        assert!(!out.status.success(), "{args:?} succeeded");
        String::from_utf8(out.stderr).unwrap()
    };
    let e = fails(&[photo, "--corners", "10,10,390,10,390,290,10,500"]);
    assert!(
        e.contains("bottom-left") && e.contains("outside the photo (400 x 300)"),
        "{e}"
    );
    let e = fails(&[photo, "--corners", "10,10,390,290,390,10,10,290"]);
    assert!(
        e.contains("convex") && e.contains("top-left, top-right, bottom-right, bottom-left"),
        "{e}"
    );
    let e = fails(&[photo, "--corners", "10,10,390,10,390"]);
    assert!(e.contains("5 numbers"), "{e}");
    let e = fails(&[
        photo,
        "--corners",
        "10,10,390,10,390,290,10,290",
        "--puck-colour",
        "120,120,125",
    ]);
    assert!(
        e.contains("--puck-colour 120,120,125") && e.contains("grey"),
        "{e}"
    );
    let e = fails(&[
        "/no/such/photo.jpg",
        "--corners",
        "10,10,390,10,390,290,10,290",
    ]);
    assert!(e.contains("/no/such/photo.jpg"), "{e}");
    let e = fails(&[
        photo,
        "--corners",
        "10,10,390,10,390,290,10,290",
        "--arena",
        "thesis",
    ]);
    assert!(e.contains("--arena thesis"), "{e}");
    // An empty screen: no pucks, and so no formed shape to report.
    let out = Command::new(HOST)
        .args([
            "observe",
            "--photo",
            photo,
            "--corners",
            "10,10,390,10,390,290,10,290",
        ])
        .output()
        .unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        out.status.success() && text.contains("pucks found: 0 (the arena places 12)"),
        "{text}"
    );
    assert!(text.contains("not formed"), "{text}");
}
