//! Physical quantities on the command line: `15mm`, `"25 ms"`, `0.015` (plain numbers are SI),
//! parsed by the same unit parser as the scene format ([`material::quantity::Quantity`]).

use material::quantity::{Dim, Quantity};

/// Parse `s` as a quantity of dimension `dim` (SI value); `flag` names the option in errors.
pub fn quantity(s: &str, dim: Dim, flag: &str) -> Result<f64, String> {
    let v = Quantity::parse(s)
        .and_then(|q| q.get(dim))
        .map_err(|e| format!("{flag}: {e}"))?;
    if !v.is_finite() {
        return Err(format!("{flag}: `{s}` is not finite"));
    }
    Ok(v)
}

/// A length in m.
pub fn length(s: &str, flag: &str) -> Result<f64, String> {
    quantity(s, Dim::LENGTH, flag)
}

/// A time in s.
pub fn time(s: &str, flag: &str) -> Result<f64, String> {
    quantity(s, Dim::TIME, flag)
}

/// A comma-separated list of `n` lengths (m), e.g. `-50mm,195mm`.
pub fn lengths(s: &str, n: usize, flag: &str) -> Result<Vec<f64>, String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| length(x, flag))
        .collect::<Result<_, _>>()?;
    if v.len() != n {
        return Err(format!(
            "{flag}: expected {n} comma-separated lengths, got `{s}`"
        ));
    }
    Ok(v)
}
