//! The contact stage of the time loop (placeholder; being written).

use crate::scene::contact_spec::{ContactScene, HandScene, IndenterScene};
use crate::simulation::{ForceStage, Simulation};
use std::path::Path;

/// Adapter from the `contact` crate to the solver's force-stage interface.
pub struct ContactForceStage;

impl ForceStage for ContactForceStage {
    fn name(&self) -> &'static str {
        "contact"
    }
    fn apply(
        &mut self,
        _t: f64,
        _dt: f64,
        _x: &[[f64; 3]],
        _v: &[[f64; 3]],
        _force: &mut [[f64; 3]],
    ) {
    }
    fn energy(&self) -> f64 {
        0.0
    }
}

/// Build the contact stage for a scene.
pub fn build_stage(
    _sim: &Simulation,
    _indenters: &[IndenterScene],
    _hands: &[HandScene],
    _contact: Option<&ContactScene>,
    path: &Path,
    _src: &str,
) -> Result<ContactForceStage, String> {
    Err(format!(
        "{}: contact is not implemented yet",
        path.display()
    ))
}
