//! The line parser of `palpa predict --stdin`: one JSON object per line,
//! `{"x": m, "y": m, "force": N, "phase": optional, "id": optional}`. Its own file, depending on `serde_json`
//! only, so that the fuzz harness (`fuzz/`, docs/fuzzing.md) compiles the same code.

use serde_json::Value;

/// One input value, which must be a finite number.
pub fn check_finite(name: &str, v: f64) -> Result<f64, String> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{name} = {v} is not a finite number"))
    }
}

/// One input line: the press, the respiratory phase when given, and the `id` to echo.
#[derive(Debug, PartialEq)]
pub struct InputLine {
    /// x [m], y [m], force [N].
    pub press: [f64; 3],
    /// The respiratory phase, 0 (exhalation) .. 1 (inspiration).
    pub phase: Option<f64>,
    /// Echoed back.
    pub id: Option<Value>,
}

/// One JSON input line.
pub fn parse_line(text: &str) -> Result<InputLine, String> {
    let v: Value = serde_json::from_str(text).map_err(|e| format!("not JSON: {e}"))?;
    let Value::Object(mut obj) = v else {
        return Err(r#"expected an object {"x": .., "y": .., "force": ..}"#.into());
    };
    let id = obj.remove("id");
    let has_phase = obj.contains_key("phase");
    let mut take = |name: &str, unit: &str| -> Result<f64, String> {
        match obj.remove(name) {
            None => Err(format!("missing field \"{name}\" (a number, {unit})")),
            Some(Value::Number(n)) => {
                let v = n
                    .as_f64()
                    .ok_or_else(|| format!("field \"{name}\": {n} is not a number"))?;
                check_finite(name, v)
            }
            Some(other) => Err(format!(
                "field \"{name}\": expected a plain number ({unit}), got {other}"
            )),
        }
    };
    let press = [take("x", "m")?, take("y", "m")?, take("force", "N")?];
    let phase = match has_phase {
        true => Some(check_phase(take("phase", "0 .. 1")?)?),
        false => None,
    };
    if let Some(k) = obj.keys().next() {
        return Err(format!(
            "unknown field \"{k}\" (expected x, y, force and optionally phase and id)"
        ));
    }
    Ok(InputLine { press, phase, id })
}

/// A respiratory phase within 0 (exhalation) .. 1 (inspiration).
pub fn check_phase(v: f64) -> Result<f64, String> {
    if (0.0..=1.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!(
            "phase = {v} is outside 0 (exhalation) .. 1 (inspiration)"
        ))
    }
}

/// One raw stdin line: `None` for a blank line (skipped), else its input or the error for its
/// reply (a line that is not UTF-8 is an error; the stream goes on).
pub fn parse_input_line(buf: &[u8]) -> Result<Option<InputLine>, String> {
    std::str::from_utf8(buf)
        .map_err(|e| format!("not valid UTF-8 ({e})"))
        .and_then(|line| {
            if line.trim().is_empty() {
                Ok(None)
            } else {
                parse_line(line).map(Some)
            }
        })
}
