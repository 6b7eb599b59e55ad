//! `ContactStage::apply` must not allocate: a counting global allocator watches a run of a
//! two-finger hand with friction and damping pressing and sliding over a spring-supported
//! surface (so broad-phase rebuilds, force control and friction all happen).
//!
//! Only the test's own thread is counted: the test harness's main thread may still be
//! bookkeeping (and allocating) while the run goes, and its allocations are not `apply`'s.
#![allow(clippy::needless_range_loop)]

mod common;
use common::*;
use contact::*;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;
static COUNT: AtomicUsize = AtomicUsize::new(0);
thread_local! {
    /// Whether this thread's allocations are counted (a `const` Cell: reading it never allocates).
    static ON: Cell<bool> = const { Cell::new(false) };
}

fn counting() -> bool {
    ON.try_with(Cell::get).unwrap_or(false)
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        if counting() {
            COUNT.fetch_add(1, Ordering::Relaxed);
        }
        System.alloc(l)
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        System.dealloc(p, l)
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        if counting() {
            COUNT.fetch_add(1, Ordering::Relaxed);
        }
        System.realloc(p, l, n)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn apply_does_not_allocate() {
    let h = 1e-3;
    let (x0, surf) = flat_grid(60, h, 1e8);
    let m = 1e-5;
    let hand = HandSpec {
        name: "hand".into(),
        point: [30e-3, 30e-3, 0.0],
        direction: [0.0, 0.0, -1.0],
        spacing_axis: None,
        diameter: 8e-3,
        spacing: 16e-3,
        length: 50e-3,
        tilt: 0.2,
        gap: 0.5e-3,
        motion: MotionSpec::Force(ForceControl {
            ramp_time: 0.01,
            ..ForceControl::new(10.0)
        }),
        friction: Some(0.2),
    }
    .to_indenter_spec()
    .unwrap();
    let slider = IndenterSpec {
        name: "slider".into(),
        parts: vec![ShapeSpec::Sphere {
            center: [5e-3, 5e-3, 3e-3 - 0.3e-3],
            radius: 3e-3,
        }],
        direction: [1.0, 0.0, 0.0],
        motion: MotionSpec::Velocity {
            curve: Curve::Constant { value: 0.5 },
        },
        friction: None,
    };
    let params = ContactParams {
        damping_ratio: 0.1,
        ..Default::default()
    };
    let mut st = ContactStage::new(&[hand, slider], surf, &x0, &vec![m; x0.len()], params).unwrap();
    let mut body = SpringSurface::new(x0, m, 100.0, 1e-3);
    let dt = 1e-5;
    for i in 0..50 {
        body.step(&mut st, i as f64 * dt, dt);
    }
    let rebuilds0 = st.counters().0;
    ON.with(|on| on.set(true));
    for i in 50..3000 {
        body.step(&mut st, i as f64 * dt, dt);
    }
    ON.with(|on| on.set(false));
    let n = COUNT.load(Ordering::SeqCst);
    let (rebuilds, faces, samples) = st.counters();
    eprintln!(
        "allocations {n}; rebuilds {}; faces visited {faces}; samples {samples}; hand {:.3} N",
        rebuilds - rebuilds0,
        st.indenters()[0].reaction
    );
    assert!(
        rebuilds > rebuilds0 + 5,
        "the run must exercise broad-phase rebuilds"
    );
    assert!(st.indenters()[0].reaction > 1.0 && st.indenters()[1].reaction > 0.0);
    assert_eq!(n, 0, "apply allocated");
}
