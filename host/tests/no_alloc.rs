//! The steady-state step loop allocates nothing, with or without learning.

use sim::control::orbital::{OrbitalConfig, OrbitalConstruction};
use sim::{config::SimConfig, fields::ScalarField, simulation::Simulation};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::Arc;

struct Counting;

thread_local! {
    /// Allocations of this thread, so that tests running beside each other
    /// (and the test harness) do not count each other's.
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

fn count() {
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

fn allocations() -> u64 {
    ALLOCATIONS.with(Cell::get)
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn stepping_allocates_nothing() {
    let mut config = SimConfig::default();
    config.world.innies = 4;
    // no episode ends (a reset draws new bodies): Eval never exceeds 1
    config.episode.success_eval = 1.0;
    let thresholds = config.thresholds.clone();
    let mut sim = Simulation::new(config, Arc::new(ScalarField::annulus()), 4).unwrap();
    let mut controller = OrbitalConstruction::new(OrbitalConfig::default(), &thresholds);
    sim.run(&mut controller, 1000);
    let before = allocations();
    sim.run(&mut controller, 20_000);
    assert_eq!(allocations() - before, 0);
}

#[test]
fn learning_allocates_nothing() {
    let mut config = SimConfig::default();
    config.episode.success_eval = 1.0;
    let mut sim = Simulation::new(config, Arc::new(ScalarField::annulus()), 5).unwrap();
    let mut learner = host::learn::QLearner::new(host::learn::LearnConfig::default()).unwrap();
    sim.run(&mut learner, 1000);
    let before = allocations();
    sim.run(&mut learner, 20_000);
    assert_eq!(allocations() - before, 0);
}

#[test]
fn stepping_with_the_robots_senses_allocates_nothing_once_warmed_up() {
    let scenario = sim::scenario::Scenario {
        sensors: sim::scenario::sensor_setup::SensorSetup::Robot(Box::default()),
        controller: sim::scenario::ControllerChoice::Random,
        ..sim::scenario::Scenario::default()
    };
    let (mut sim, mut controller) = scenario.build().unwrap();
    // the camera's buffers grow to the most bodies a frame has seen
    sim.run(&mut controller, 2000);
    let before = allocations();
    sim.run(&mut controller, 5000);
    assert_eq!(allocations() - before, 0);
}
