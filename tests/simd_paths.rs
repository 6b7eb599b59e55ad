//! The AVX-512 element kernels and the baseline ones give bitwise the same run: a coarse press
//! of the phantom (8 mm voxels, 3 mm in 3 ms: the flesh's rubber law, the liver's Ogden + Prony,
//! the ribs' plasticity) with `PALPA_SIMD=baseline` and without, in `f64` (where the AVX-512 path
//! runs its own lane type, `material::real_avx512::Z64x8`) and in `f32`, one-point and F-bar.
//! On a processor without AVX-512 both runs take the baseline path and the test shows nothing
//! (it says so).

#[path = "support/cli.rs"]
mod cli;

use std::path::Path;

/// `history.csv` and `roi_stress.csv` of a coarse press (3 mm in 3 ms) with `extra` options.
fn press(out: &Path, baseline: bool, extra: &[&str]) -> (Vec<u8>, Vec<u8>) {
    let mut c = cli::coarse_press(out, 3, extra);
    if baseline {
        c.env("PALPA_SIMD", "baseline");
    } else {
        c.env_remove("PALPA_SIMD");
    }
    let o = c.output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && !err.contains("panicked"), "{err}");
    let read = |f: &str| std::fs::read(out.join(f)).unwrap();
    (read("history.csv"), read("roi_stress.csv"))
}

#[test]
fn avx512_and_baseline_kernels_agree_bitwise() {
    #[cfg(target_arch = "x86_64")]
    let avx512 = std::arch::is_x86_feature_detected!("avx512f")
        && std::arch::is_x86_feature_detected!("avx512dq")
        && std::arch::is_x86_feature_detected!("avx512vl")
        && std::arch::is_x86_feature_detected!("avx512bw");
    #[cfg(not(target_arch = "x86_64"))]
    let avx512 = false;
    if !avx512 {
        eprintln!("no AVX-512 on this processor: both runs would take the baseline path");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for (k, extra) in [
        &["--precision", "f64"][..],
        &["--precision", "f32"][..],
        &["--precision", "f64", "--element", "full_fbar"][..],
    ]
    .iter()
    .enumerate()
    {
        let a = press(&dir.path().join(format!("avx512-{k}")), false, extra);
        let b = press(&dir.path().join(format!("baseline-{k}")), true, extra);
        assert!(
            a.0 == b.0,
            "{extra:?}: history.csv differs between the kernels"
        );
        assert!(
            a.1 == b.1,
            "{extra:?}: roi_stress.csv differs between the kernels"
        );
        assert!(a.0.len() > 100, "{extra:?}: the history is empty");
    }
}
