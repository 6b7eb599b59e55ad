//! The messages of `palpa serve`'s WebSocket (and of its stdin stream): JSON objects, one per
//! WebSocket text message or stdin line, with a `"type"`. Units are SI and stated per field.
//!
//! From a client:
//!
//! | type | fields | |
//! |---|---|---|
//! | `pointer` | `x`, `y` [m, body plan frame], `force` [N, >= 0], `stamp`? | a press where the pointer is |
//! | `plate` | `corners` [4 x [f_x, f_y, f_z] N, or 4 x f_z], `moments`? [4 x [m_x, m_y, m_z] N m], `t`? [s], `stamp`? | one reading of the force plate's load cells |
//! | `phase` | `value` [0 .. 1] | respiratory phase |
//! | `replay` | `action`: `start` or `stop` | the server's `--replay` log |
//! | `deviation_map` | `force`? [N] | the GP's predictive deviation over the picture (to this client only) |
//!
//! `stamp` is the sender's wall-clock time of the input [ms since the Unix epoch], echoed in the
//! frame it causes, for measuring latency; `t` is the sensor's own clock [s] for the force
//! filter (the server's clock when absent). Anything else is an error sent back to the sender
//! alone (`{"type": "error", "error": "..."}`): text that is not JSON or not an object, a missing
//! or unknown type, an unknown or missing field, a number that is not finite, a negative force
//! or one above [`MAX_FORCE_N`], a position beyond [`MAX_POSITION_M`], a message longer than
//! [`MAX_MESSAGE_BYTES`]. The server keeps serving.

use serde::Deserialize;
use serde_json::Value;
use surrogate::sensor::CornerLoads;

/// Longest message the server reads (bytes); a plate message takes about 300.
pub const MAX_MESSAGE_BYTES: usize = 16 * 1024;

/// Largest force a press may ask for [N]: a palpation is tens of newtons.
pub const MAX_FORCE_N: f64 = 1000.0;

/// Largest plan coordinate a press may have [m]: a body is well inside it, and a position
/// given in millimetres by mistake is well outside.
pub const MAX_POSITION_M: f64 = 2.0;

/// A replay command.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ReplayAction {
    /// Play the log from its start.
    Start,
    /// Stop playing.
    Stop,
}

/// One message from a client, checked.
#[derive(Clone, Debug, PartialEq)]
pub enum ClientMessage {
    /// A press at (x, y) [m] with `force` [N].
    Pointer {
        x: f64,
        y: f64,
        force: f64,
        stamp: Option<f64>,
    },
    /// A plate reading.
    Plate {
        loads: CornerLoads,
        t: Option<f64>,
        stamp: Option<f64>,
    },
    /// The respiratory phase.
    Phase { value: f64 },
    /// Start or stop the replay.
    Replay { action: ReplayAction },
    /// Ask for the deviation map (at `force` [N], or the current force).
    DeviationMap { force: Option<f64> },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PointerMsg {
    x: f64,
    y: f64,
    force: f64,
    #[serde(default)]
    stamp: Option<f64>,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum Corner {
    Normal(f64),
    Full([f64; 3]),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PlateMsg {
    corners: [Corner; 4],
    #[serde(default)]
    moments: Option<[[f64; 3]; 4]>,
    #[serde(default)]
    t: Option<f64>,
    #[serde(default)]
    stamp: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PhaseMsg {
    value: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ReplayMsg {
    action: ReplayAction,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DeviationMsg {
    #[serde(default)]
    force: Option<f64>,
}

const TYPES: &str = "pointer, plate, phase, replay or deviation_map";

fn finite(name: &str, v: f64, unit: &str) -> Result<f64, String> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{name} = {v} is not a finite number ({unit})"))
    }
}

fn force_ok(name: &str, f: f64) -> Result<f64, String> {
    let f = finite(name, f, "N")?;
    if f < 0.0 {
        return Err(format!(
            "{name} = {f} N is negative: a press pushes, give a force >= 0"
        ));
    }
    if f > MAX_FORCE_N {
        return Err(format!(
            "{name} = {f} N is above {MAX_FORCE_N} N, not a palpation (the unit is N)"
        ));
    }
    Ok(f)
}

fn position_ok(name: &str, v: f64) -> Result<f64, String> {
    let v = finite(name, v, "m")?;
    if v.abs() > MAX_POSITION_M {
        return Err(format!(
            "{name} = {v} m is more than {MAX_POSITION_M} m from the origin: not on a body \
             (the unit is m, not mm)"
        ));
    }
    Ok(v)
}

fn stamp_ok(s: Option<f64>) -> Result<Option<f64>, String> {
    s.map(|v| finite("stamp", v, "ms since the Unix epoch"))
        .transpose()
}

/// Parses and checks one message.
pub fn parse(text: &str) -> Result<ClientMessage, String> {
    if text.len() > MAX_MESSAGE_BYTES {
        return Err(format!(
            "message of {} bytes is longer than the limit of {MAX_MESSAGE_BYTES} bytes",
            text.len()
        ));
    }
    let v: Value = serde_json::from_str(text).map_err(|e| format!("not JSON: {e}"))?;
    let Value::Object(mut obj) = v else {
        return Err(format!(
            "expected a JSON object with a \"type\" ({TYPES}), got {}",
            kind_of(&v)
        ));
    };
    let ty = match obj.remove("type") {
        Some(Value::String(s)) => s,
        Some(other) => return Err(format!("\"type\" must be a string, got {other}")),
        None => return Err(format!("missing \"type\" ({TYPES})")),
    };
    let rest = Value::Object(obj);
    let bad = |e: serde_json::Error| format!("{ty} message: {e}");
    match ty.as_str() {
        "pointer" => {
            let m: PointerMsg = serde_json::from_value(rest).map_err(bad)?;
            Ok(ClientMessage::Pointer {
                x: position_ok("x", m.x)?,
                y: position_ok("y", m.y)?,
                force: force_ok("force", m.force)?,
                stamp: stamp_ok(m.stamp)?,
            })
        }
        "plate" => {
            let m: PlateMsg = serde_json::from_value(rest).map_err(bad)?;
            let mut loads = CornerLoads {
                force: [[0.0; 3]; 4],
                moment: m.moments,
            };
            for (k, c) in m.corners.iter().enumerate() {
                loads.force[k] = match *c {
                    Corner::Normal(fz) => [0.0, 0.0, fz],
                    Corner::Full(f) => f,
                };
            }
            let t = m.t.map(|t| finite("t", t, "s")).transpose()?;
            Ok(ClientMessage::Plate {
                loads,
                t,
                stamp: stamp_ok(m.stamp)?,
            })
        }
        "phase" => {
            let m: PhaseMsg = serde_json::from_value(rest).map_err(bad)?;
            let v = finite("value", m.value, "phase, 0 .. 1")?;
            if !(0.0..=1.0).contains(&v) {
                return Err(format!(
                    "phase value = {v} is outside 0 (exhalation) .. 1 (inspiration)"
                ));
            }
            Ok(ClientMessage::Phase { value: v })
        }
        "replay" => {
            let m: ReplayMsg = serde_json::from_value(rest).map_err(bad)?;
            Ok(ClientMessage::Replay { action: m.action })
        }
        "deviation_map" => {
            let m: DeviationMsg = serde_json::from_value(rest).map_err(bad)?;
            let force = m.force.map(|f| force_ok("force", f)).transpose()?;
            Ok(ClientMessage::DeviationMap { force })
        }
        other => Err(format!("unknown type \"{other}\" (expected {TYPES})")),
    }
}

fn kind_of(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn good_messages() {
        assert_eq!(
            parse(r#"{"type":"pointer","x":-0.07,"y":0.18,"force":30,"stamp":1.5}"#).unwrap(),
            ClientMessage::Pointer {
                x: -0.07,
                y: 0.18,
                force: 30.0,
                stamp: Some(1.5)
            }
        );
        match parse(r#"{"type":"plate","corners":[1,2,[0.5,0,3],4],"t":0.01}"#).unwrap() {
            ClientMessage::Plate { loads, t, stamp } => {
                assert_eq!(loads.force[1], [0.0, 0.0, 2.0]);
                assert_eq!(loads.force[2], [0.5, 0.0, 3.0]);
                assert_eq!((t, stamp), (Some(0.01), None));
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(
            parse(r#"{"type":"phase","value":0.5}"#).unwrap(),
            ClientMessage::Phase { value: 0.5 }
        );
        assert_eq!(
            parse(r#"{"type":"replay","action":"stop"}"#).unwrap(),
            ClientMessage::Replay {
                action: ReplayAction::Stop
            }
        );
    }

    /// Each bad message gets an error that says what is wrong.
    #[test]
    fn bad_messages_are_named() {
        let cases = [
            ("{not json", "not JSON"),
            ("[1,2]", "got an array"),
            (r#"{"x":1}"#, "missing \"type\""),
            (r#"{"type":"poke"}"#, "unknown type \"poke\""),
            (r#"{"type":"pointer","x":0,"y":0,"force":-3}"#, "negative"),
            (
                r#"{"type":"pointer","x":0,"y":0,"force":5000}"#,
                "not a palpation",
            ),
            (r#"{"type":"pointer","x":0,"y":0}"#, "missing field `force`"),
            (
                r#"{"type":"pointer","x":0,"y":0,"force":1,"z":2}"#,
                "unknown field `z`",
            ),
            (r#"{"type":"pointer","x":NaN,"y":0,"force":1}"#, "not JSON"),
            (
                r#"{"type":"pointer","x":1e999,"y":0,"force":1}"#,
                "not JSON",
            ),
            (
                r#"{"type":"pointer","x":"a","y":0,"force":1}"#,
                "pointer message",
            ),
            (r#"{"type":"plate","corners":[1,2,3]}"#, "plate message"),
            (r#"{"type":"phase","value":2}"#, "outside 0"),
            (
                r#"{"type":"replay","action":"rewind"}"#,
                "unknown variant `rewind`",
            ),
        ];
        for (text, expect) in cases {
            let e = parse(text).unwrap_err();
            assert!(e.contains(expect), "{text}: {e}");
        }
        let long = format!(
            r#"{{"type":"pointer","x":0,"y":0,"force":1,"pad":"{}"}}"#,
            "a".repeat(MAX_MESSAGE_BYTES)
        );
        assert!(parse(&long).unwrap_err().contains("longer than the limit"));
    }
}
