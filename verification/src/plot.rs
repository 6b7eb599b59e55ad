//! Convergence and comparison plots (PNG, plotters' bitmap backend), drawn in memory with the
//! embedded font ([`picture`]) and written atomically.

use crate::Series;
use plotters::prelude::*;
use std::path::Path;

const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

fn range(v: impl Iterator<Item = f64>, log: bool) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for x in v.filter(|x| x.is_finite() && (!log || *x > 0.0)) {
        lo = lo.min(x);
        hi = hi.max(x);
    }
    if !(hi >= lo) {
        return None;
    }
    if log {
        Some((lo / 1.5, hi * 1.5))
    } else {
        let pad = 0.05 * (hi - lo).max(1e-12 * hi.abs().max(1.0));
        Some((lo - pad, hi + pad))
    }
}

/// Draw one series into `dir/<plot>.png`; returns the file name.
pub fn draw(s: &Series, dir: &Path) -> Result<String, String> {
    let name = format!("{}.png", s.plot);
    let path = dir.join(&name);
    let e = |e: &dyn std::fmt::Display| format!("plot `{name}`: {e}");
    let pts = || s.curves.iter().flat_map(|c| c.1.iter().copied());
    let (x0, x1) = range(pts().map(|p| p.0), s.log).ok_or_else(|| e(&"no data"))?;
    let (y0, y1) = range(pts().map(|p| p.1), s.log).ok_or_else(|| e(&"no data"))?;
    const SIZE: (u32, u32) = (900, 600);
    picture::register_fonts();
    let mut rgb = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|x| e(&x))?;
        macro_rules! body {
            ($chart:expr) => {{
                let mut chart = $chart;
                chart
                    .configure_mesh()
                    .x_label_formatter(&|v| tick(*v))
                    .y_label_formatter(&|v| tick(*v))
                    .x_desc(s.axes.0.as_str())
                    .y_desc(s.axes.1.as_str())
                    .draw()
                    .map_err(|x| e(&x))?;
                for (k, (label, c)) in s.curves.iter().enumerate() {
                    let col = COLORS[k % COLORS.len()];
                    let data: Vec<(f64, f64)> = c
                        .iter()
                        .copied()
                        .filter(|p| {
                            p.0.is_finite()
                                && p.1.is_finite()
                                && (!s.log || (p.0 > 0.0 && p.1 > 0.0))
                        })
                        .collect();
                    let many = data.len() > 40;
                    chart
                        .draw_series(LineSeries::new(data.clone(), col.stroke_width(2)))
                        .map_err(|x| e(&x))?
                        .label(label.as_str())
                        .legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2))
                        });
                    if !many {
                        chart
                            .draw_series(data.iter().map(|p| Circle::new(*p, 4, col.filled())))
                            .map_err(|x| e(&x))?;
                    }
                }
                chart
                    .configure_series_labels()
                    .background_style(WHITE.mix(0.8))
                    .border_style(BLACK)
                    .draw()
                    .map_err(|x| e(&x))?;
            }};
        }
        let mut builder = ChartBuilder::on(&root);
        builder
            .caption(s.title.as_str(), ("sans-serif", 22))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(70);
        if s.log {
            body!(builder
                .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
                .map_err(|x| e(&x))?);
        } else {
            body!(builder
                .build_cartesian_2d(x0..x1, y0..y1)
                .map_err(|x| e(&x))?);
        }
        root.present().map_err(|x| e(&x))?;
    }
    let png = picture::encode_png(&rgb, SIZE.0, SIZE.1).map_err(|x| e(&x))?;
    solver::output::atomic::write_atomic(&path, &png).map_err(|x| e(&x))?;
    Ok(name)
}

/// A tick label: the value rounded to six significant digits and printed shortest, so that a
/// log axis's 0.6 reads `0.6` and not `0.6000000000000001`, and a tick of 1e-7 stays 1e-7.
fn tick(v: f64) -> String {
    let rounded: f64 = format!("{v:.5e}").parse().unwrap_or(v);
    format!("{rounded}")
}
