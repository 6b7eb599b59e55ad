//! Respiratory phases of a campaign's locations: 0 (exhalation, the paper's frame) to 1
//! (inspiration), the liver `phase * max_liver_shift` caudal of its place at 0
//! ([`phantom::PhantomParams::liver_shift`]).

/// A respiratory phase: finite, 0 (exhalation) .. 1 (inspiration).
pub fn check_phase(p: f64, key: &str) -> Result<(), String> {
    if (0.0..=1.0).contains(&p) {
        Ok(())
    } else {
        Err(format!(
            "{key}: phase {p} is outside 0 (exhalation) .. 1 (inspiration)"
        ))
    }
}
