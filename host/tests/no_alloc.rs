//! The steady-state step loop allocates nothing.

use host::controller::{OrbitalConfig, OrbitalConstruction};
use host::sim::{ScalarField, SimConfig, Simulation};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

struct Counting;

static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
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
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    sim.run(&mut controller, 20_000);
    assert_eq!(ALLOCATIONS.load(Ordering::Relaxed) - before, 0);
}
