//! Numbers in saved files that may be NaN or infinite. JSON has neither: serde_json writes them
//! as `null`, and reading `null` back into an `f64` fails. A model trained on test samples
//! whose stresses do not vary has a Fit of NaN (`1 - |Y - Yhat| / |Y - mean|` divides by zero),
//! and such a model saved fine but could not be loaded. Fields marked
//! `#[serde(with = "crate::json_f64")]` write a non-finite value as `null` and read `null` as NaN.

use serde::{Deserialize, Deserializer, Serializer};

/// A finite value as a number, anything else as `null`.
pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
    if x.is_finite() {
        s.serialize_f64(*x)
    } else {
        s.serialize_none()
    }
}

/// A number, or NaN for `null`.
pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// The same for `Option<f64>`, where `null` already means `None` (for a pooled test Fit: no
/// test samples): a non-finite value is written as the string `"NaN"` and read back as NaN.
pub mod option {
    use serde::{Deserialize, Deserializer, Serializer};

    /// A finite value as a number, a non-finite one as `"NaN"`, `None` as `null`.
    pub fn serialize<S: Serializer>(x: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
        match x {
            Some(v) if v.is_finite() => s.serialize_f64(*v),
            Some(_) => s.serialize_str("NaN"),
            None => s.serialize_none(),
        }
    }

    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Stored {
        Number(f64),
        Text(String),
    }

    /// A number, `"NaN"`, or `null` for `None`.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
        match Option::<Stored>::deserialize(d)? {
            None => Ok(None),
            Some(Stored::Number(v)) => Ok(Some(v)),
            Some(Stored::Text(t)) if t == "NaN" => Ok(Some(f64::NAN)),
            Some(Stored::Text(t)) => Err(serde::de::Error::custom(format!(
                "expected a number, \"NaN\" or null, got \"{t}\""
            ))),
        }
    }
}

#[cfg(test)]
mod tests {
    use serde::{Deserialize, Serialize};

    #[derive(Serialize, Deserialize)]
    struct Fits {
        #[serde(with = "crate::json_f64")]
        fit: f64,
        #[serde(with = "crate::json_f64::option")]
        test: Option<f64>,
    }

    #[test]
    fn a_nan_fit_is_saved_as_null_and_read_back_as_nan() {
        let s = serde_json::to_string(&Fits {
            fit: f64::NAN,
            test: Some(f64::INFINITY),
        })
        .unwrap();
        assert_eq!(s, r#"{"fit":null,"test":"NaN"}"#);
        let back: Fits = serde_json::from_str(&s).unwrap();
        assert!(back.fit.is_nan() && back.test.is_some_and(f64::is_nan));
        let back: Fits = serde_json::from_str(r#"{"fit":1.0,"test":null}"#).unwrap();
        assert_eq!(back.test, None);
        let back: Fits = serde_json::from_str(r#"{"fit":0.93,"test":0.9}"#).unwrap();
        assert_eq!((back.fit, back.test), (0.93, Some(0.9)));
    }
}
