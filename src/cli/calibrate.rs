//! `palpa calibrate PRESSES.csv --out calibration.json`: fit the force plate's map to the body
//! ([`surrogate::sensor::calibration`]) from presses recorded at known body points.
//!
//! PRESSES.csv is a sensor log ([`surrogate::sensor::log`]: `time_s`, the four cells' loads
//! `c1_fz_N` .. `c4_fz_N`, optionally their shear and moments) with the known body point of each
//! row in `x_m`, `y_m` (m, the model's plan frame). Each row's centre of pressure on the plate
//! is computed from the cells; rows below the contact threshold (no press) are left out, rows
//! the plate refuses (a pull, a press off the plate) are reported and left out; the affine
//! map is fitted by least squares to the rest, and the fit's residuals are printed, overall and
//! per known point. The file is written atomically.

use super::units;
use std::path::PathBuf;
use surrogate::sensor::{Affine2, Calibration, Plate, PlateReading, SensorLog};

/// `palpa calibrate`'s arguments.
#[derive(clap::Args, Debug)]
pub struct CalibrateArgs {
    /// The recorded presses: a sensor log with the known body point of each row (x_m, y_m).
    pub presses: PathBuf,
    /// Where to write the calibration (JSON).
    #[arg(long)]
    pub out: PathBuf,
    /// Plate size along its x and y, e.g. 400mm,400mm (plain numbers: m).
    #[arg(long, default_value = "400mm,400mm")]
    pub plate_size: String,
    /// Half spans of the load cells' rectangle along x and y [default: half the plate size,
    /// a cell at each corner].
    #[arg(long)]
    pub cell_half_span: Option<String>,
    /// Depth of the cells' measuring points below the plate's top surface.
    #[arg(long, default_value = "0mm")]
    pub cell_depth: String,
    /// Normal force below which the plate counts as not pressed [N].
    #[arg(long, default_value_t = 1.0)]
    pub contact_threshold: f64,
}

/// Run `palpa calibrate`.
pub fn calibrate(a: &CalibrateArgs) -> Result<(), String> {
    let size = units::lengths(&a.plate_size, 2, "--plate-size")?;
    let half = match &a.cell_half_span {
        Some(s) => units::lengths(s, 2, "--cell-half-span")?,
        None => vec![size[0] / 2.0, size[1] / 2.0],
    };
    let plate = Plate {
        size_m: [size[0], size[1]],
        cell_half_span_m: [half[0], half[1]],
        cell_depth_m: units::length(&a.cell_depth, "--cell-depth")?,
        contact_threshold_n: a.contact_threshold,
    };
    plate.validate().map_err(|e| e.to_string())?;
    let log = SensorLog::read(&a.presses).map_err(|e| e.to_string())?;
    let name = a.presses.display();
    for e in &log.errors {
        eprintln!("{name}: {e} (row left out)");
    }
    let (mut pairs, mut lifted, mut refused) = (Vec::new(), 0usize, 0usize);
    for (k, s) in log.samples.iter().enumerate() {
        let Some(point) = s.point_m else {
            return Err(format!(
                "{name}: no x_m, y_m columns: a calibration needs the known body point of each press"
            ));
        };
        match plate.resolve(&s.loads) {
            Ok(PlateReading::Press { cop_m, .. }) => pairs.push((cop_m, point)),
            Ok(PlateReading::NoContact { .. }) => lifted += 1,
            Err(e) => {
                refused += 1;
                eprintln!("{name}: row {} (t = {} s): {e} (left out)", k + 1, s.time_s);
            }
        }
    }
    let (map, stats) = Affine2::fit(&pairs).map_err(|e| format!("{name}: {e}"))?;
    let cal = Calibration {
        fit: Some(stats),
        affine: map,
        plate,
        ..Calibration::centred_at([0.0, 0.0])
    };
    cal.write(&a.out)
        .map_err(|e| format!("{}: {e}", a.out.display()))?;

    let [[a11, a12], [a21, a22]] = map.a;
    let det = a11 * a22 - a12 * a21;
    println!(
        "palpa calibrate: {} presses at {} known points fitted ({lifted} rows without a press, \
         {refused} refused, {} unreadable)",
        stats.samples,
        stats.points,
        log.errors.len()
    );
    println!("body [x, y] = A [u, v] + b (m):");
    println!(
        "  A = [[{a11:.5}, {a12:.5}], [{a21:.5}, {a22:.5}]]  (det {det:.4}{})",
        if det < 0.0 { ", mirrored" } else { "" }
    );
    println!("  b = [{:.5}, {:.5}]", map.b[0], map.b[1]);
    println!(
        "  residuals: RMS {:.2} mm, largest {:.2} mm",
        stats.rms_m * 1e3,
        stats.max_m * 1e3
    );
    // per known point: mean residual, to find a bad press
    let mut points: Vec<[f64; 2]> = pairs.iter().map(|p| p.1).collect();
    points.sort_by(|p, q| p[0].total_cmp(&q[0]).then(p[1].total_cmp(&q[1])));
    points.dedup();
    for p in points {
        let r: Vec<f64> = pairs
            .iter()
            .filter(|q| q.1 == p)
            .map(|(u, x)| {
                let y = map.apply(*u);
                (y[0] - x[0]).hypot(y[1] - x[1])
            })
            .collect();
        println!(
            "  at ({:7.1}, {:7.1}) mm: {} presses, mean residual {:.2} mm",
            p[0] * 1e3,
            p[1] * 1e3,
            r.len(),
            r.iter().sum::<f64>() / r.len() as f64 * 1e3
        );
    }
    println!("saved {}", a.out.display());
    Ok(())
}
