//! `palpa palpate`'s `roi_stress_map.png` draws the live view's picture (issue 27): a quick
//! coarse press (8 mm voxels, 3 mm in 3 ms), then the map's size, a title in the title band,
//! and the colour of the largest ROI stress of the last sample (from `roi_stress.csv`) on its
//! scale, which the cell drawn last (the largest) must show.

#[path = "support/cli.rs"]
mod cli;

use std::path::Path;
use std::process::Output;
use surrogate::ColourScale;

/// A quick coarse press into `out` ([`cli::coarse_press`]), run.
fn coarse_press(out: &Path, depth_mm: u32, extra: &[&str]) -> Output {
    cli::coarse_press(out, depth_mm, extra).output().unwrap()
}

#[test]
fn palpate_draws_the_stress_picture() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("p");
    let o = coarse_press(&out, 3, &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && !err.contains("panicked"), "{err}");
    // the last sample's stresses: the last column of roi_stress.csv
    let csv = std::fs::read_to_string(out.join("roi_stress.csv")).unwrap();
    let last: Vec<f64> = csv
        .lines()
        .skip(1)
        .map(|l| l.rsplit(',').next().unwrap().parse().unwrap())
        .collect();
    assert!(last.len() > 10);
    let scale = ColourScale::of_values(&last);
    let top = last.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let want = scale.rgb(top);

    let dec = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(out.join("roi_stress_map.png")).unwrap(),
    ));
    let mut r = dec.read_info().unwrap();
    let mut buf = vec![0; r.output_buffer_size().unwrap()];
    let info = r.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), surrogate::render::SIZE);
    assert_eq!(info.color_type, png::ColorType::Rgb);
    let w = info.width as usize;
    let px = |x: usize, y: usize| &buf[(y * w + x) * 3..(y * w + x) * 3 + 3];
    let ink = (12..28)
        .flat_map(|y| (20..600).map(move |x| (x, y)))
        .filter(|&(x, y)| px(x, y)[0] < 80)
        .count();
    assert!(ink > 300, "the title is drawn: {ink} dark pixels");
    let hot = buf.chunks(3).filter(|p| *p == want).count();
    assert!(
        hot >= 20,
        "the largest stress's colour {want:?} covers {hot} pixels"
    );
    force_csv_is_history_and_its_moving_average(&out);
}

/// `force_indentation.csv` holds history.csv's hand travel and reaction row for row, and as
/// `force_filtered` their centred 1 ms moving average (recomputed here by its definition,
/// the mean over |t_j - t_i| <= 0.5 ms), which cannot peak above the raw force and chatters
/// less (its total variation is smaller).
fn force_csv_is_history_and_its_moving_average(out: &Path) {
    use solver::output::history::{column, read_history};
    let table = |name: &str| read_history(&out.join(name)).unwrap();
    let col =
        |(head, rows): &(Vec<String>, Vec<Vec<f64>>), name: &str| column(head, rows, name).unwrap();
    let history = table("history.csv");
    let forces = table("force_indentation.csv");
    let t = col(&forces, "time");
    let f = col(&forces, "force");
    let smooth = col(&forces, "force_filtered");
    assert_eq!(t, col(&history, "time"));
    assert_eq!(col(&forces, "indentation"), col(&history, "hand_travel"));
    assert_eq!(f, col(&history, "hand_reaction"));
    for (i, &ti) in t.iter().enumerate() {
        let window: Vec<f64> = (0..t.len())
            .filter(|&j| t[j] >= ti - 0.5e-3 && t[j] <= ti + 0.5e-3)
            .map(|j| f[j])
            .collect();
        let mean = window.iter().sum::<f64>() / window.len() as f64;
        let tol = 1e-9 * f.iter().fold(1.0, |m: f64, v| m.max(v.abs()));
        assert!(
            (smooth[i] - mean).abs() <= tol,
            "row {i}: {} vs {mean}",
            smooth[i]
        );
    }
    let top = |v: &[f64]| v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let variation = |v: &[f64]| v.windows(2).map(|w| (w[1] - w[0]).abs()).sum::<f64>();
    let tol = 1e-12 * top(&f);
    assert!(top(&smooth) <= top(&f) + tol && top(&f) > 0.0);
    assert!(
        variation(&smooth) < variation(&f),
        "{} vs {}",
        variation(&smooth),
        variation(&f)
    );
}

/// `--fidelity fast` runs the physical hourglass form with the flesh's K/G capped at 5000: the
/// summary states the preset with its error budget and the bulk moduli that ran
/// (`summary.json`: the flesh's K = 5000 G, the ribs' cap not binding).
#[test]
fn the_fast_preset_states_itself_and_the_bulk_moduli_it_ran() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("f");
    let o = coarse_press(&out, 2, &["--fidelity", "fast"]);
    let text = String::from_utf8_lossy(&o.stdout);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{text}{err}");
    assert!(
        text.contains("fidelity: fast") && text.contains("ROI stress Fit"),
        "{text}"
    );
    let scene = std::fs::read_to_string(out.join("scene.toml")).unwrap();
    assert!(scene.contains("hourglass = \"physical\""), "{scene}");
    assert!(scene.contains("target_dt = \"1.3 x initial\""), "{scene}");
    assert!(scene.contains("precision = \"f32\""), "{scene}");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let bulk = s["bulk_modulus"].as_array().unwrap();
    let flesh = bulk.iter().find(|b| b["part"] == "flesh").unwrap();
    let (k, g) = (
        flesh["applied_pa"].as_f64().unwrap(),
        flesh["shear_pa"].as_f64().unwrap(),
    );
    assert!((k / g - 5000.0).abs() < 1e-6, "K/G = {}", k / g);
    let ribs = bulk.iter().find(|b| b["part"] == "ribs").unwrap();
    assert_eq!(ribs["applied_pa"], ribs["original_pa"]);
}

/// An option for a knob the fast preset sets, given beside it, is refused before anything
/// runs, naming the knobs, with a non-zero exit and no panic.
#[test]
fn a_knob_beside_the_fast_preset_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    for extra in [
        ["--mass-scaling", "off"],
        ["--element", "full_fbar"],
        ["--precision", "f64"],
        ["--max-bulk-ratio", "100"],
    ] {
        let out = dir.path().join("x");
        let o = coarse_press(&out, 2, &["--fidelity", "fast", extra[0], extra[1]]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{extra:?}: accepted");
        assert!(
            err.contains("--fidelity fast sets")
                && err.contains(extra[0])
                && !err.contains("panicked"),
            "{extra:?}: {err}"
        );
        assert!(!out.join("summary.json").exists(), "{extra:?} ran");
    }
}

/// A `--max-bulk-ratio` that no material can have is refused before anything runs, naming the
/// option, with a non-zero exit and no panic.
#[test]
fn an_impossible_bulk_ratio_is_refused_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    for bad in ["NaN", "0.5", "-3", "inf"] {
        let o = coarse_press(
            &dir.path().join("k"),
            2,
            &[&format!("--max-bulk-ratio={bad}")],
        );
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{bad}: accepted");
        assert!(
            err.contains("max bulk ratio") && !err.contains("panicked"),
            "{bad}: {err}"
        );
    }
}
