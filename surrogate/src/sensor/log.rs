//! Recorded sensor logs: CSV, one row per reading of the four load cells, replayed by
//! `palpa serve --replay` at recorded speed and read by `palpa calibrate`.
//!
//! Columns (the header names them, with their units; any order; `#` starts a comment line):
//!
//! | column | unit | |
//! |---|---|---|
//! | `time_s` | s | required, non-decreasing |
//! | `c1_fz_N` .. `c4_fz_N` | N | required: each cell's normal load (a press is positive) |
//! | `cK_fx_N`, `cK_fy_N` | N | optional shear per cell (0 when absent) |
//! | `cK_mx_Nm`, `cK_my_Nm`, `cK_mz_Nm` | N m | optional cell moments |
//! | `x_m`, `y_m` | m | optional, together: the known body point of a calibration press |
//!
//! Cells are numbered as in [`super::plate`]. An unknown column is an error naming it; a row
//! that cannot be used (wrong field count, not a number, not finite, time going back) is
//! reported with its line number and skipped, and the rest of the log is kept.

use super::plate::CornerLoads;
use crate::dataset::write_atomic;
use crate::error::{Error, Result};
use std::fmt::Write as _;
use std::io::Write;
use std::path::Path;

/// One row of a log.
#[derive(Clone, Debug, PartialEq)]
pub struct LogSample {
    /// Time [s].
    pub time_s: f64,
    /// The four cells' loads.
    pub loads: CornerLoads,
    /// The known body point [m] (calibration presses).
    pub point_m: Option<[f64; 2]>,
}

/// A parsed log: its usable rows and the reasons the others were skipped.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SensorLog {
    /// Usable rows, in order.
    pub samples: Vec<LogSample>,
    /// `line N: reason` for each skipped row.
    pub errors: Vec<String>,
}

/// Where each field of a row goes.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Field {
    Time,
    Force(usize, usize),
    Moment(usize, usize),
    X,
    Y,
}

fn field_of(name: &str) -> Option<Field> {
    match name {
        "time_s" => return Some(Field::Time),
        "x_m" => return Some(Field::X),
        "y_m" => return Some(Field::Y),
        _ => {}
    }
    let rest = name.strip_prefix('c')?;
    let (k, rest) = rest.split_at(1);
    let k: usize = k.parse().ok().filter(|k| (1..=4).contains(k))?;
    let axis = |c: &str| ["x", "y", "z"].iter().position(|a| *a == c);
    if let Some(ax) = rest.strip_prefix("_f").and_then(|r| r.strip_suffix("_N")) {
        return axis(ax).map(|a| Field::Force(k - 1, a));
    }
    if let Some(ax) = rest.strip_prefix("_m").and_then(|r| r.strip_suffix("_Nm")) {
        return axis(ax).map(|a| Field::Moment(k - 1, a));
    }
    None
}

/// The header of a log with these optional columns.
fn header(moments: bool, points: bool) -> Vec<String> {
    let mut h = vec!["time_s".to_string()];
    for k in 1..=4 {
        for a in ["x", "y", "z"] {
            h.push(format!("c{k}_f{a}_N"));
        }
        if moments {
            for a in ["x", "y", "z"] {
                h.push(format!("c{k}_m{a}_Nm"));
            }
        }
    }
    if points {
        h.push("x_m".into());
        h.push("y_m".into());
    }
    h
}

impl SensorLog {
    /// Parses log text (see the module doc). Header errors are errors; row errors are
    /// collected in `errors`.
    pub fn parse(text: &str) -> Result<SensorLog> {
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
        let (_, head) = lines
            .next()
            .ok_or_else(|| Error::invalid("log", "empty: no header line"))?;
        let mut fields = Vec::new();
        for name in head.split(',').map(str::trim) {
            let f = field_of(name).ok_or_else(|| {
                Error::invalid(
                    "log header",
                    format!(
                        "unknown column \"{name}\" (expected time_s, c1_fz_N .. c4_fz_N, \
                         optionally cK_fx_N, cK_fy_N, cK_mx_Nm .. cK_mz_Nm, x_m and y_m)"
                    ),
                )
            })?;
            if fields.contains(&f) {
                return Err(Error::invalid(
                    "log header",
                    format!("column \"{name}\" appears twice"),
                ));
            }
            fields.push(f);
        }
        let need = std::iter::once(Field::Time).chain((0..4).map(|k| Field::Force(k, 2)));
        for f in need {
            if !fields.contains(&f) {
                let name = match f {
                    Field::Force(k, _) => format!("c{}_fz_N", k + 1),
                    _ => "time_s".into(),
                };
                return Err(Error::invalid(
                    "log header",
                    format!("missing column \"{name}\""),
                ));
            }
        }
        let has_x = fields.contains(&Field::X);
        if has_x != fields.contains(&Field::Y) {
            return Err(Error::invalid(
                "log header",
                "give both x_m and y_m, or neither",
            ));
        }
        let has_m = fields.iter().any(|f| matches!(f, Field::Moment(..)));
        let mut log = SensorLog::default();
        let mut last_t = f64::NEG_INFINITY;
        for (i, line) in lines {
            let n = i + 1;
            let parts: Vec<&str> = line.split(',').map(str::trim).collect();
            if parts.len() != fields.len() {
                log.errors.push(format!(
                    "line {n}: {} fields, the header has {}",
                    parts.len(),
                    fields.len()
                ));
                continue;
            }
            let mut s = LogSample {
                time_s: 0.0,
                loads: CornerLoads {
                    force: [[0.0; 3]; 4],
                    moment: has_m.then_some([[0.0; 3]; 4]),
                },
                point_m: has_x.then_some([0.0; 2]),
            };
            let mut bad = None;
            for (f, text) in fields.iter().zip(&parts) {
                let v = match text.parse::<f64>() {
                    Ok(v) if v.is_finite() => v,
                    _ => {
                        bad = Some(format!("line {n}: \"{text}\" is not a finite number"));
                        break;
                    }
                };
                match *f {
                    Field::Time => s.time_s = v,
                    Field::Force(k, a) => s.loads.force[k][a] = v,
                    Field::Moment(k, a) => {
                        if let Some(m) = s.loads.moment.as_mut() {
                            m[k][a] = v;
                        }
                    }
                    Field::X => {
                        if let Some(p) = s.point_m.as_mut() {
                            p[0] = v;
                        }
                    }
                    Field::Y => {
                        if let Some(p) = s.point_m.as_mut() {
                            p[1] = v;
                        }
                    }
                }
            }
            if let Some(e) = bad {
                log.errors.push(e);
                continue;
            }
            if s.time_s < last_t {
                log.errors.push(format!(
                    "line {n}: time {} s is before the previous row's {} s",
                    s.time_s, last_t
                ));
                continue;
            }
            last_t = s.time_s;
            log.samples.push(s);
        }
        Ok(log)
    }

    /// Reads and parses the log at `path`.
    pub fn read(path: &Path) -> Result<SensorLog> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        SensorLog::parse(&text).map_err(|e| Error::format(path, e.to_string()))
    }

    /// The log's CSV text (moment and point columns when any sample has them).
    pub fn to_csv(&self) -> String {
        let moments = self.samples.iter().any(|s| s.loads.moment.is_some());
        let points = self.samples.iter().any(|s| s.point_m.is_some());
        let mut out = header(moments, points).join(",");
        out.push('\n');
        for s in &self.samples {
            let _ = write!(out, "{}", s.time_s);
            for k in 0..4 {
                for v in s.loads.force[k] {
                    let _ = write!(out, ",{v}");
                }
                if moments {
                    let m = s.loads.moment.unwrap_or([[0.0; 3]; 4]);
                    for v in m[k] {
                        let _ = write!(out, ",{v}");
                    }
                }
            }
            if points {
                let p = s.point_m.unwrap_or([f64::NAN; 2]);
                let _ = write!(out, ",{},{}", p[0], p[1]);
            }
            out.push('\n');
        }
        out
    }

    /// Writes the log's CSV to `path` atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        let text = self.to_csv();
        write_atomic(path, |mut f| {
            f.write_all(text.as_bytes()).map_err(|e| Error::io(path, e))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_with_moments_and_points() {
        let mut loads = CornerLoads::default();
        loads.force[2] = [0.5, -0.25, 12.0];
        let mut m = [[0.0; 3]; 4];
        m[1][0] = 0.125;
        loads.moment = Some(m);
        let log = SensorLog {
            samples: vec![
                LogSample {
                    time_s: 0.0,
                    loads: loads.clone(),
                    point_m: Some([-0.05, 0.2]),
                },
                LogSample {
                    time_s: 0.01,
                    loads,
                    point_m: Some([-0.04, 0.19]),
                },
            ],
            errors: vec![],
        };
        let back = SensorLog::parse(&log.to_csv()).unwrap();
        assert_eq!(back, log);
    }

    /// Only fz columns, in another order, with a comment; bad rows are named and skipped.
    #[test]
    fn minimal_columns_and_bad_rows() {
        let text = "# a press\nc4_fz_N,c3_fz_N,c2_fz_N,c1_fz_N,time_s\n\
                    1,2,3,4,0.00\n1,2,3,NaN,0.01\n1,2,3,0.02\n5,5,5,5,0.02\n1,2,3,4,0.01\n";
        let log = SensorLog::parse(text).unwrap();
        assert_eq!(log.samples.len(), 2);
        assert_eq!(log.samples[0].loads.force[0][2], 4.0);
        assert_eq!(log.samples[0].loads.force[3][2], 1.0);
        assert_eq!(log.samples[0].loads.moment, None);
        assert_eq!(log.errors.len(), 3, "{:?}", log.errors);
        assert!(log.errors[0].starts_with("line 4:") && log.errors[0].contains("NaN"));
        assert!(log.errors[1].contains("4 fields"));
        assert!(log.errors[2].contains("before the previous"));
    }

    #[test]
    fn header_errors() {
        let e = SensorLog::parse("time_s,c1_fz_N,c2_fz_N,c3_fz_N,c4_fz_N,c5_fz_N\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("unknown column \"c5_fz_N\""), "{e}");
        let e = SensorLog::parse("time_s,c1_fz_N,c2_fz_N,c3_fz_N\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing column \"c4_fz_N\""), "{e}");
        let e = SensorLog::parse("time_s,c1_fz_N,c2_fz_N,c3_fz_N,c4_fz_N,x_m\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("x_m and y_m"), "{e}");
        assert!(SensorLog::parse("").is_err());
    }
}
