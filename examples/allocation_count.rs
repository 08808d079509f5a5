//! Counts heap allocations on the paper rotor's hot paths (the issue's "no allocation inside the
//! iteration loop"): one eigen-solve, one linearisation, one cost evaluation, and one damped
//! estimation of Table 3 case 1. A counting global allocator wraps the system one.
//!
//! `cargo run --release --example allocation_count`

use eigenfit::core::eigen::{BandedSolver, DenseSolver, EigenSolver};

use eigenfit::core::measurement::Measurement;

use eigenfit::core::model::StructuralModel;

use eigenfit::core::problem::Problem;

use eigenfit::core::sensitivity::Sensitivities;

use eigenfit::core::update::{Driver, LevenbergMarquardt};
use eigenfit::rotor::presets::paper_rotor;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations made by `f`, after one warm-up call (the solver's per-thread workspace).
fn count<T>(mut f: impl FnMut() -> T) -> usize {
    std::hint::black_box(f());
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    std::hint::black_box(f());
    ALLOCATIONS.load(Ordering::Relaxed) - before
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let rotor = paper_rotor();
    let p = [1e5, 1e5];
    let system = rotor.assemble(&p)?;
    let f = DenseSolver.lowest(&system, 2)?.frequencies_hz();
    let problem = Problem::new(&rotor, BandedSolver::default(), Measurement::from_frequencies(&f)?);
    println!("heap allocations, paper rotor, banded solver (after a warm-up call):");
    println!("  assemble K, M                      {:>5}", count(|| rotor.assemble(&p)));
    println!(
        "  eigen-solve, lowest 2 modes        {:>5}",
        count(|| BandedSolver::default().lowest(&system, 2))
    );
    println!(
        "  modes + sensitivities (2 modes)    {:>5}",
        count(|| Sensitivities::compute(&rotor, &BandedSolver::default(), &p, 2))
    );
    println!("  one linearisation                  {:>5}", count(|| problem.linearise(&[1e3, 2e4])));
    println!("  one cost evaluation                {:>5}", count(|| problem.cost(&[1e3, 2e4])));
    let run = |restarts: bool| {
        let mut damped = if restarts {
            LevenbergMarquardt::default()
        } else {
            LevenbergMarquardt::default().with_max_restarts(0)
        };
        Driver::default().run(&problem, &mut damped, &[1e2, 1e2])
    };
    let estimate = run(true)?;
    println!(
        "  damped, Table 3 case 1              {:>5}  ({} iterations, {} evaluations)",
        count(|| run(true)),
        estimate.iterations,
        estimate.evaluations
    );
    println!("  damped without the coarse-grid start {:>3}", count(|| run(false)));
    Ok(())
}
