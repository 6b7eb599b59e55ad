//! 2-D map of ROI stress, like the paper's projection: each ROI element's centroid projected on
//! the x-y plane, coloured by its value, with a colour bar.
//!
//! Colours: a diverging blue-white-red scale centred on zero when the values take both signs
//! (compression blue, tension red), else the half of that scale for the values' sign.
//! Text needs a system font; where none is found, the map is drawn without labels.

use crate::error::{Error, Result};
use ndarray::ArrayView2;
use plotters::prelude::*;
use std::path::Path;

/// Image size in pixels.
const SIZE: (u32, u32) = (900, 700);

/// Renders `values` (one per ROI element, Pa) at the x-y projection of `centroids` (R x 3, m)
/// to the PNG file `path`. The axes are in mm and the colour bar in kPa.
pub fn render_map(centroids: ArrayView2<f64>, values: &[f64], path: &Path) -> Result<()> {
    let r = values.len();
    if centroids.nrows() != r || centroids.ncols() < 2 {
        return Err(Error::invalid(
            "centroids",
            format!(
                "shape {:?} for {r} values (expected R x 3)",
                centroids.dim()
            ),
        ));
    }
    if r == 0 {
        return Err(Error::invalid("values", "nothing to draw"));
    }
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(Error::invalid("values", format!("entry {i} is not finite")));
    }
    let fail = |e: &dyn std::fmt::Display| Error::format(path, format!("rendering: {e}"));
    let (lo, hi) = value_range(values);
    let xs: Vec<f64> = centroids.column(0).iter().map(|v| v * 1e3).collect();
    let ys: Vec<f64> = centroids.column(1).iter().map(|v| v * 1e3).collect();
    let (x0, x1) = padded(&xs);
    let (y0, y1) = padded(&ys);

    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let (map_area, bar_area) = root.split_horizontally(SIZE.0 - 140);
    let with_text = ChartBuilder::on(&map_area)
        .caption("ROI maximum principal stress", ("sans-serif", 24))
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(55)
        .build_cartesian_2d(x0..x1, y0..y1);
    let mut chart = match with_text {
        Ok(c) => c,
        Err(_) => ChartBuilder::on(&map_area)
            .margin(15)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| fail(&e))?,
    };
    let mesh = chart
        .configure_mesh()
        .x_desc("x [mm]")
        .y_desc("y [mm]")
        .disable_mesh()
        .draw();
    if mesh.is_err() {
        chart
            .configure_mesh()
            .disable_mesh()
            .x_labels(0)
            .y_labels(0)
            .draw()
            .map_err(|e| fail(&e))?;
    }
    chart
        .draw_series(
            xs.iter()
                .zip(&ys)
                .zip(values)
                .map(|((&x, &y), &v)| Circle::new((x, y), 5, colour(v, lo, hi).filled())),
        )
        .map_err(|e| fail(&e))?;

    // colour bar: a column of rectangles from lo (bottom) to hi (top), labelled in kPa
    let (bw, bh) = bar_area.dim_in_pixel();
    let (top, bottom) = (60i32, bh as i32 - 60);
    let steps = 200;
    for k in 0..steps {
        let t = k as f64 / (steps - 1) as f64;
        let v = lo + t * (hi - lo);
        let yk = bottom - ((bottom - top) as f64 * t) as i32;
        let h = ((bottom - top) as f64 / steps as f64).ceil() as i32 + 1;
        bar_area
            .draw(&Rectangle::new(
                [(20, yk - h), (50, yk)],
                colour(v, lo, hi).filled(),
            ))
            .map_err(|e| fail(&e))?;
    }
    bar_area
        .draw(&Rectangle::new(
            [(20, top), (50, bottom)],
            BLACK.stroke_width(1),
        ))
        .map_err(|e| fail(&e))?;
    let style = ("sans-serif", 16).into_font().color(&BLACK);
    for k in 0..=4 {
        let t = k as f64 / 4.0;
        let v = lo + t * (hi - lo);
        let yk = bottom - ((bottom - top) as f64 * t) as i32;
        // labels are best effort: without a system font the bar is drawn unlabelled
        let _ = bar_area.draw(&Text::new(
            format!("{:.2}", v / 1e3),
            (56, yk - 8),
            style.clone(),
        ));
    }
    let _ = bar_area.draw(&Text::new("kPa", (20, top - 30), style));
    let _ = bw;
    root.present().map_err(|e| fail(&e))?;
    Ok(())
}

/// Colour range: symmetric about zero when the values change sign, else their min..max.
fn value_range(values: &[f64]) -> (f64, f64) {
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let (lo, hi) = if lo < 0.0 && hi > 0.0 {
        let m = lo.abs().max(hi);
        (-m, m)
    } else {
        (lo, hi)
    };
    if hi - lo > 0.0 {
        (lo, hi)
    } else {
        (lo - 1.0, hi + 1.0)
    }
}

fn padded(v: &[f64]) -> (f64, f64) {
    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let pad = ((hi - lo) * 0.05).max(1.0);
    (lo - pad, hi + pad)
}

/// Blue (lo) - white (middle) - red (hi).
fn colour(v: f64, lo: f64, hi: f64) -> RGBColor {
    let mut t = ((v - lo) / (hi - lo)).clamp(0.0, 1.0);
    // one sign only: white at zero stress, the half of the scale of that sign
    if lo >= 0.0 {
        t = 0.5 + 0.5 * t;
    } else if hi <= 0.0 {
        t *= 0.5;
    }
    let lerp = |a: f64, b: f64, s: f64| (a + (b - a) * s).round() as u8;
    if t < 0.5 {
        let s = t / 0.5;
        RGBColor(
            lerp(59.0, 247.0, s),
            lerp(76.0, 247.0, s),
            lerp(192.0, 247.0, s),
        )
    } else {
        let s = (t - 0.5) / 0.5;
        RGBColor(
            lerp(247.0, 180.0, s),
            lerp(247.0, 4.0, s),
            lerp(247.0, 38.0, s),
        )
    }
}
