//! Criterion benchmark of one simulation step (sensors, controller,
//! physics, Eval at the check interval) in the `host bench` configurations.

use criterion::{criterion_group, criterion_main, Criterion};
use host::bench::BenchVariant;

fn step(c: &mut Criterion) {
    for (name, variant) in [
        ("standard", BenchVariant::default()),
        (
            "naive",
            BenchVariant {
                naive: true,
                ..BenchVariant::default()
            },
        ),
        (
            "scale",
            BenchVariant {
                scale: true,
                ..BenchVariant::default()
            },
        ),
        (
            "robot",
            BenchVariant {
                robot_senses: true,
                ..BenchVariant::default()
            },
        ),
    ] {
        let (mut sim, mut controller) = match variant.scenario().build() {
            Ok(built) => built,
            Err(e) => panic!("cannot build the {name} scenario: {e:#}"),
        };
        // warm up past the start, where every body is still unsettled
        sim.run(&mut controller, variant.warm_up().max(2000));
        c.bench_function(&format!("step/{name}"), |b| {
            b.iter(|| sim.step(&mut controller))
        });
    }
}

criterion_group!(benches, step);
criterion_main!(benches);
