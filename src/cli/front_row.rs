//! One point of `palpa front`: its cells as `front.csv` and `front.md` write them, and a row
//! read back from an earlier `front.csv` (`--with`), so that a front measured in another sitting
//! is drawn beside new designs without its campaigns. Each row carries the settings it was
//! measured with (target, training samples, likelihood rows, phase input;
//! [`super::selection::SampleTargetArgs::settings`]), and `--with` refuses rows measured with
//! other settings than the front's own: their Fits are not comparable. A `front.csv` written
//! before the `settings` column (9 columns) is read with its settings unknown, said on stderr,
//! and written back as `unknown`.

use std::path::Path;

/// `front.csv`'s header; `--with` reads files that start with it, or with its first 9 columns.
pub const CSV_HEADER: &str =
    "design,runs,core_hours,fit_heldout,fit_abc,fit_other,fit_paper_times,coverage_95,train_seconds,settings";

/// The columns of a `front.csv` written before the `settings` column.
const COLUMNS_BEFORE_SETTINGS: usize = 9;

/// The `settings` cell of a row whose settings are not known.
const UNKNOWN: &str = "unknown";

/// One point of the front.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// The design's name (NAME of NAME=DIR).
    pub design: String,
    /// Training runs (locations) the GP learned from.
    pub runs: usize,
    /// Those runs' solver cost: wall time times threads (core-hours).
    pub core_hours: f64,
    /// Held-out Fit (paper eq. 5) over every held-out location.
    pub fit_all: f64,
    /// Held-out Fit over A, B and C, when the campaign holds them out.
    pub fit_abc: Option<f64>,
    /// Held-out Fit over the other held-out locations, if any.
    pub fit_other: Option<f64>,
    /// Held-out Fit at the paper's time stamps.
    pub fit_paper_times: f64,
    /// Share of held-out values inside the GP's 95 % intervals.
    pub coverage: Option<f64>,
    /// The GP's training time (s).
    pub train_seconds: f64,
    /// What the model learned and how ([`super::selection::SampleTargetArgs::settings`]);
    /// `None` for a row of a `front.csv` that does not record them.
    pub settings: Option<String>,
}

impl Row {
    /// The row's cells as `front.csv` writes them.
    pub fn csv_cells(&self) -> Vec<String> {
        let mut cells = self.cells(false).to_vec();
        let settings = self.settings.as_deref().unwrap_or(UNKNOWN);
        debug_assert!(
            !settings.contains(','),
            "a settings cell with a comma: {settings}"
        );
        cells.push(settings.to_string());
        cells
    }

    /// The row's measured cells as `front.csv` (`md` false) or `front.md` (coverage in %, fewer
    /// digits) writes them.
    pub fn cells(&self, md: bool) -> [String; 9] {
        let o = |v: Option<f64>| v.map_or(String::new(), |f| format!("{f:.4}"));
        let coverage = if md {
            self.coverage
                .map_or("-".into(), |c| format!("{:.1} %", 100.0 * c))
        } else {
            o(self.coverage)
        };
        [
            self.design.clone(),
            self.runs.to_string(),
            if md {
                format!("{:.3}", self.core_hours)
            } else {
                format!("{:.4}", self.core_hours)
            },
            format!("{:.4}", self.fit_all),
            o(self.fit_abc),
            o(self.fit_other),
            format!("{:.4}", self.fit_paper_times),
            coverage,
            if md {
                format!("{:.1}", self.train_seconds)
            } else {
                format!("{:.2}", self.train_seconds)
            },
        ]
    }

    /// The rows of the earlier fronts at `paths` (`--with`), in order; a point (design and run
    /// count) given twice is refused, and so is a row measured with other `settings`.
    pub fn read_fronts(paths: &[std::path::PathBuf], settings: &str) -> Result<Vec<Row>, String> {
        let mut rows: Vec<Row> = Vec::new();
        for path in paths {
            let more = Row::read_csv(path)?;
            if let Some(r) = more.iter().find(|r| r.settings.is_none()) {
                eprintln!(
                    "  note: --with {}: the settings of some rows are unknown (a front.csv older than its `settings` column), e.g. {} at {} runs: they are drawn as they are, not checked against {settings}",
                    path.display(),
                    r.design,
                    r.runs
                );
            }
            if let Some((r, there)) = more.iter().find_map(|r| {
                r.settings
                    .as_deref()
                    .filter(|&s| s != settings)
                    .map(|s| (r, s))
            }) {
                return Err(format!(
                    "--with {}: {} at {} runs was measured with {there}, this front with {settings}: their Fits are not comparable (give the same --recover, --train-interval, --likelihood-rows and --ignore-phase)",
                    path.display(),
                    r.design,
                    r.runs
                ));
            }
            for (k, r) in more.iter().enumerate() {
                let twice = |o: &Row| o.design == r.design && o.runs == r.runs;
                if rows.iter().chain(&more[..k]).any(twice) {
                    return Err(format!(
                        "--with {}: design `{}` at {} runs is given twice",
                        path.display(),
                        r.design,
                        r.runs
                    ));
                }
            }
            rows.extend(more);
        }
        Ok(rows)
    }

    /// The rows of an earlier `front.csv` at `path`; a bad file is named with its line and
    /// column.
    pub fn read_csv(path: &Path) -> Result<Vec<Row>, String> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("--with {}: cannot read: {e}", path.display()))?;
        let mut lines = text.lines().enumerate();
        let columns = match lines.next() {
            Some((_, h)) if h.trim() == CSV_HEADER => CSV_HEADER.split(',').count(),
            Some((_, h))
                if h.trim()
                    .split(',')
                    .eq(CSV_HEADER.split(',').take(COLUMNS_BEFORE_SETTINGS)) =>
            {
                COLUMNS_BEFORE_SETTINGS
            }
            _ => {
                return Err(format!(
                    "--with {}:1: not a front.csv (its header must be `{CSV_HEADER}`, or the same without `,settings`)",
                    path.display()
                ))
            }
        };
        lines
            .filter(|(_, l)| !l.trim().is_empty())
            .map(|(i, l)| {
                Row::parse(l, columns)
                    .map_err(|e| format!("--with {}:{}: {e}", path.display(), i + 1))
            })
            .collect()
    }

    /// One data line of a `front.csv` of `columns` columns.
    fn parse(line: &str, columns: usize) -> Result<Row, String> {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        if cells.len() != columns {
            return Err(format!("{} cells, the header has {columns}", cells.len()));
        }
        let names: Vec<&str> = CSV_HEADER.split(',').collect();
        let num = |k: usize| {
            cells[k]
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("{}: `{}` is not a number", names[k], cells[k]))
        };
        let maybe = |k: usize| (!cells[k].is_empty()).then(|| num(k)).transpose();
        if cells[0].is_empty() {
            return Err("design: empty".into());
        }
        Ok(Row {
            design: cells[0].to_string(),
            runs: cells[1]
                .parse()
                .map_err(|_| format!("runs: `{}` is not a count", cells[1]))?,
            core_hours: num(2)?,
            fit_all: num(3)?,
            fit_abc: maybe(4)?,
            fit_other: maybe(5)?,
            fit_paper_times: num(6)?,
            coverage: maybe(7)?,
            train_seconds: num(8)?,
            settings: match cells.get(9) {
                Some(s) if s.is_empty() => return Err("settings: empty".into()),
                Some(&UNKNOWN) | None => None,
                Some(s) => Some(s.to_string()),
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::{Row, CSV_HEADER};

    #[test]
    fn a_written_row_reads_back_and_bad_cells_are_named() {
        let row = Row {
            design: "sobol".into(),
            runs: 25,
            core_hours: 1.0597,
            fit_all: 0.9433,
            fit_abc: Some(0.9452),
            fit_other: None,
            fit_paper_times: 0.9358,
            coverage: Some(0.9101),
            train_seconds: 50.16,
            settings: Some("element stress; every sample; 600 likelihood rows".into()),
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("front.csv");
        let line = row.csv_cells().join(",");
        std::fs::write(&path, format!("{CSV_HEADER}\n{line}\n")).unwrap();
        assert_eq!(Row::read_csv(&path).unwrap(), vec![row.clone()]);
        // the same settings are read back, other settings are refused by name
        let paths = [path.clone()];
        assert_eq!(
            Row::read_fronts(&paths, "element stress; every sample; 600 likelihood rows")
                .unwrap()
                .len(),
            1
        );
        let err = Row::read_fronts(
            &paths,
            "recovered H = 5 mm; every sample; 600 likelihood rows",
        )
        .unwrap_err();
        assert!(
            err.contains("sobol at 25 runs was measured with element stress; every sample; 600 likelihood rows, this front with recovered"),
            "{err}"
        );
        // a front.csv of 9 columns reads with its settings unknown, joins a front of any
        // settings, and writes them as `unknown`, which reads back as unknown
        let old = CSV_HEADER.rsplit_once(',').unwrap().0;
        std::fs::write(&path, format!("{old}\n{}\n", row.cells(false).join(","))).unwrap();
        let read = Row::read_fronts(
            &paths,
            "recovered H = 5 mm; every sample; 600 likelihood rows",
        )
        .unwrap();
        assert_eq!(read[0].settings, None);
        assert_eq!(read[0].fit_all, row.fit_all);
        let line = read[0].csv_cells().join(",");
        assert!(line.ends_with(",unknown"), "{line}");
        std::fs::write(&path, format!("{CSV_HEADER}\n{line}\n")).unwrap();
        assert_eq!(Row::read_csv(&path).unwrap(), read);
        std::fs::write(
            &path,
            format!("{CSV_HEADER}\n{}\n", line.replace("0.9433", "x")),
        )
        .unwrap();
        let err = Row::read_csv(&path).unwrap_err();
        assert!(
            err.contains("front.csv:2: fit_heldout: `x` is not a number"),
            "{err}"
        );
        std::fs::write(&path, "runs,fit\n1,2\n").unwrap();
        let err = Row::read_csv(&path).unwrap_err();
        assert!(err.contains("front.csv:1: not a front.csv"), "{err}");
    }
}
