//! A row of `palpa study` ([`StudyRow`]): one setting of one knob, its cost and its errors,
//! from the palpation study ([`crate::study`]) or its Hertz block ([`crate::study_hertz`]).

use scene::run::RunStatus;

/// One run of the study.
#[derive(Clone, Debug)]
pub struct StudyRow {
    /// The knob varied: `mesh`, `element`, `mass scaling`, `dt factor` (or `hertz ...`).
    pub knob: String,
    /// Its setting, e.g. `voxel 6 mm`.
    pub setting: String,
    /// What the errors are measured against: the knob's most accurate setting, or the closed
    /// form for the Hertz block.
    pub against: String,
    /// Elements.
    pub elements: usize,
    /// Steps.
    pub steps: u64,
    /// Elements x steps.
    pub element_cycles: f64,
    /// Wall time of the time loop and output (s).
    pub wall: f64,
    /// Added mass, percent of the physical mass.
    pub added_mass_percent: f64,
    /// Peak hand force (N).
    pub peak_force: f64,
    /// Relative RMS force error against `against`.
    pub force_error: f64,
    /// Relative RMS ROI stress error against `against`.
    pub stress_error: f64,
    /// How its run ended.
    pub status: RunStatus,
}

impl StudyRow {
    /// A setting whose run failed.
    pub fn failed(knob: String, setting: String, e: String) -> StudyRow {
        StudyRow {
            knob,
            setting,
            against: String::new(),
            elements: 0,
            steps: 0,
            element_cycles: 0.0,
            wall: 0.0,
            added_mass_percent: 0.0,
            peak_force: f64::NAN,
            force_error: f64::NAN,
            stress_error: f64::NAN,
            status: RunStatus::Failed(e),
        }
    }

    /// Whether the row belongs to the Hertz block.
    pub fn is_hertz(&self) -> bool {
        self.knob.starts_with("hertz")
    }
}
