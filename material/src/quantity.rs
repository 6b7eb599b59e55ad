//! Physical quantities with explicit units, as written in scene and material files.
//!
//! A quantity is either a plain number, read as SI, or a string `"<number> <unit expression>"`
//! such as `"40 kPa"`, `"1.06e-6 kg/mm^3"`, `"25 ms"`, `"15 mm"` or `"9.81 m/s^2"`.
//! The unit expression is a product of factors separated by `*`, `.` or a space, each optionally
//! raised to an integer power with `^`, and an optional single `/` after which every factor is
//! in the denominator (`kg/mm^3`, `N/mm`, `mm/ms`).
//!
//! Every unit maps to an SI factor and a dimension vector over (mass, length, time). A field of
//! a scene declares the dimension it expects, and a mismatch is an error that names the field:
//! this is what lets an LS-DYNA user paste kg-mm-ms-GPa values (`"0.04 GPa"`, `"1.06e-6 kg/mm^3"`)
//! without silent mistakes.

use serde::de::{self, Deserializer, Visitor};
use serde::Deserialize;
use std::fmt;

/// Exponents of (mass, length, time) of a physical dimension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dim(pub i8, pub i8, pub i8);

impl Dim {
    /// Dimensionless.
    pub const NONE: Dim = Dim(0, 0, 0);
    /// Length (m).
    pub const LENGTH: Dim = Dim(0, 1, 0);
    /// Time (s).
    pub const TIME: Dim = Dim(0, 0, 1);
    /// Mass (kg).
    pub const MASS: Dim = Dim(1, 0, 0);
    /// Pressure, stress, modulus (Pa).
    pub const PRESSURE: Dim = Dim(1, -1, -2);
    /// Density (kg/m^3).
    pub const DENSITY: Dim = Dim(1, -3, 0);
    /// Velocity (m/s).
    pub const VELOCITY: Dim = Dim(0, 1, -1);
    /// Acceleration (m/s^2).
    pub const ACCELERATION: Dim = Dim(0, 1, -2);
    /// Force (N).
    pub const FORCE: Dim = Dim(1, 1, -2);
    /// Energy (J).
    pub const ENERGY: Dim = Dim(1, 2, -2);
    /// Frequency, rate (1/s).
    pub const RATE: Dim = Dim(0, 0, -1);
    /// Stiffness per unit length (N/m).
    pub const STIFFNESS: Dim = Dim(1, 0, -2);

    /// `self` times `o` to the power `times`; `None` when an exponent leaves the `i8` range.
    fn add(self, o: Dim, times: i32) -> Option<Dim> {
        let e = |a: i8, b: i8| i8::try_from(a as i32 + times * b as i32).ok();
        Some(Dim(e(self.0, o.0)?, e(self.1, o.1)?, e(self.2, o.2)?))
    }

    /// A human name for error messages.
    pub fn name(self) -> String {
        let known = [
            (Dim::NONE, "a plain number"),
            (Dim::LENGTH, "a length"),
            (Dim::TIME, "a time"),
            (Dim::MASS, "a mass"),
            (Dim::PRESSURE, "a pressure/modulus"),
            (Dim::DENSITY, "a density"),
            (Dim::VELOCITY, "a velocity"),
            (Dim::ACCELERATION, "an acceleration"),
            (Dim::FORCE, "a force"),
            (Dim::ENERGY, "an energy"),
            (Dim::RATE, "a rate"),
            (Dim::STIFFNESS, "a stiffness (force/length)"),
        ];
        for (d, n) in known {
            if d == self {
                return n.to_string();
            }
        }
        format!("kg^{} m^{} s^{}", self.0, self.1, self.2)
    }
}

/// A value converted to SI, with the dimension its unit carried (`None` for a plain number,
/// which is taken as SI of whatever dimension the field expects).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quantity {
    /// The value in SI units.
    pub si: f64,
    /// The dimension given by the unit, or `None` for a bare number.
    pub dim: Option<Dim>,
}

impl Quantity {
    /// A bare SI number.
    pub fn si(v: f64) -> Self {
        Quantity { si: v, dim: None }
    }

    /// The SI value, checking that the written unit has dimension `want`.
    pub fn get(&self, want: Dim) -> Result<f64, String> {
        match self.dim {
            Some(d) if d != want => Err(format!(
                "expected {} but the unit given is {}",
                want.name(),
                d.name()
            )),
            _ => Ok(self.si),
        }
    }

    /// Parse `"<number> [unit]"`.
    pub fn parse(s: &str) -> Result<Quantity, String> {
        let t = s.trim();
        let split = t
            .char_indices()
            .find(|&(i, c)| {
                !(c.is_ascii_digit()
                    || c == '.'
                    || c == '+'
                    || c == '-'
                    || ((c == 'e' || c == 'E')
                        && t[i + 1..]
                            .starts_with(|n: char| n.is_ascii_digit() || n == '-' || n == '+')))
            })
            .map(|(i, _)| i)
            .unwrap_or(t.len());
        let (num, unit) = t.split_at(split);
        let v: f64 = num
            .trim()
            .parse()
            .map_err(|_| format!("`{s}` does not start with a number"))?;
        let unit = unit.trim();
        if unit.is_empty() {
            return Ok(Quantity::si(v));
        }
        let (f, d) = parse_unit_expr(unit)?;
        Ok(Quantity {
            si: v * f,
            dim: Some(d),
        })
    }
}

/// SI factor and dimension of a single unit symbol.
fn unit_symbol(sym: &str) -> Option<(f64, Dim)> {
    let m = Dim::MASS;
    let l = Dim::LENGTH;
    let t = Dim::TIME;
    let p = Dim::PRESSURE;
    let f = Dim::FORCE;
    let e = Dim::ENERGY;
    Some(match sym {
        "m" => (1.0, l),
        "cm" => (1e-2, l),
        "mm" => (1e-3, l),
        "um" | "µm" => (1e-6, l),
        "km" => (1e3, l),
        "s" => (1.0, t),
        "ms" => (1e-3, t),
        "us" | "µs" => (1e-6, t),
        "ns" => (1e-9, t),
        "min" => (60.0, t),
        "h" => (3600.0, t),
        "kg" => (1.0, m),
        "g" => (1e-3, m),
        "mg" => (1e-6, m),
        "t" | "tonne" => (1e3, m),
        "N" => (1.0, f),
        "mN" => (1e-3, f),
        "kN" => (1e3, f),
        "MN" => (1e6, f),
        "Pa" => (1.0, p),
        "kPa" => (1e3, p),
        "MPa" => (1e6, p),
        "GPa" => (1e9, p),
        "bar" => (1e5, p),
        "J" => (1.0, e),
        "mJ" => (1e-3, e),
        "kJ" => (1e3, e),
        "Hz" => (1.0, Dim::RATE),
        "kHz" => (1e3, Dim::RATE),
        _ => return None,
    })
}

fn parse_unit_expr(u: &str) -> Result<(f64, Dim), String> {
    let (num, den) = match u.split_once('/') {
        Some((a, b)) => {
            if b.contains('/') {
                return Err(format!("unit `{u}` has more than one `/`"));
            }
            (a, Some(b))
        }
        None => (u, None),
    };
    let mut factor = 1.0;
    let mut dim = Dim::NONE;
    for (part, sign) in [(num, 1i8), (den.unwrap_or(""), -1i8)] {
        for tok in part
            .split(|c: char| c == '*' || c == ' ' || c == '.')
            .filter(|s| !s.is_empty())
        {
            let (sym, pow) = match tok.split_once('^') {
                Some((s, p)) => (
                    s,
                    p.parse::<i8>()
                        .map_err(|_| format!("bad power `{p}` in unit `{u}`"))?,
                ),
                None => (tok, 1),
            };
            if sym == "1" && sign == 1 {
                continue;
            }
            let (f, d) = unit_symbol(sym).ok_or_else(|| {
                format!("unknown unit `{sym}` in `{u}` (known: m cm mm um s ms us kg g t N kN Pa kPa MPa GPa J Hz ...)")
            })?;
            let s = sign as i32 * pow as i32;
            factor *= f.powi(s);
            dim = dim.add(d, s).ok_or_else(|| {
                format!("unit `{u}`: its powers add up beyond what a unit can have (-128 to 127 per base unit)")
            })?;
        }
    }
    Ok((factor, dim))
}

impl<'de> Deserialize<'de> for Quantity {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Quantity;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number (SI) or a string with a unit such as \"40 kPa\"")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Quantity, E> {
                Ok(Quantity::si(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Quantity, E> {
                Ok(Quantity::si(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Quantity, E> {
                Ok(Quantity::si(v as f64))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Quantity, E> {
                Quantity::parse(v).map_err(E::custom)
            }
        }
        d.deserialize_any(V)
    }
}

/// Deserialize helpers that check the dimension at parse time, so that toml reports the
/// line and key of a wrong unit.
macro_rules! typed_quantity {
    ($(#[$doc:meta] $name:ident = $dim:expr;)*) => {$(
        #[$doc]
        #[derive(Clone, Copy, Debug, PartialEq, Default)]
        pub struct $name(pub f64);
        impl<'de> Deserialize<'de> for $name {
            fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let q = Quantity::deserialize(d)?;
                q.get($dim).map($name).map_err(de::Error::custom)
            }
        }
        impl From<$name> for f64 { fn from(x: $name) -> f64 { x.0 } }
        impl From<f64> for $name { fn from(x: f64) -> $name { $name(x) } }
    )*};
}

typed_quantity! {
    /// A length in m.
    Length = Dim::LENGTH;
    /// A time in s.
    Time = Dim::TIME;
    /// A pressure or modulus in Pa.
    Pressure = Dim::PRESSURE;
    /// A density in kg/m^3.
    Density = Dim::DENSITY;
    /// A velocity in m/s.
    Velocity = Dim::VELOCITY;
    /// An acceleration in m/s^2.
    Acceleration = Dim::ACCELERATION;
    /// A force in N.
    Force = Dim::FORCE;
    /// A mass in kg.
    Mass = Dim::MASS;
    /// A rate in 1/s.
    Rate = Dim::RATE;
    /// A dimensionless number (a unit, if given, must cancel out).
    Number = Dim::NONE;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_ls_dyna_units() {
        let q = Quantity::parse("1.06e-6 kg/mm^3").unwrap();
        assert!((q.si - 1060.0).abs() < 1e-9);
        assert_eq!(q.dim, Some(Dim::DENSITY));
        let q = Quantity::parse("0.04 GPa").unwrap();
        assert!((q.si - 4e7).abs() < 1e-6);
        let q = Quantity::parse("40 kPa").unwrap();
        assert_eq!(q.si, 4e4);
        let q = Quantity::parse("15 mm").unwrap();
        assert!((q.si - 0.015).abs() < 1e-15);
        let q = Quantity::parse("9.81 m/s^2").unwrap();
        assert_eq!(q.dim, Some(Dim::ACCELERATION));
        let q = Quantity::parse("0.6 mm/ms").unwrap();
        assert!((q.si - 0.6).abs() < 1e-12);
        assert_eq!(q.dim, Some(Dim::VELOCITY));
        let q = Quantity::parse("2.5e-3").unwrap();
        assert_eq!(q, Quantity::si(2.5e-3));
        let q = Quantity::parse("1 kg*mm/ms^2").unwrap();
        assert_eq!(q.dim, Some(Dim::FORCE));
        assert!((q.si - 1e3).abs() < 1e-9);
    }

    #[test]
    fn rejects_unknown_unit_and_wrong_dimension() {
        let e = Quantity::parse("40 kPascal").unwrap_err();
        assert!(e.contains("unknown unit `kPascal`"), "{e}");
        let e = Quantity::parse("40 kPa")
            .unwrap()
            .get(Dim::LENGTH)
            .unwrap_err();
        assert!(e.contains("expected a length"), "{e}");
        assert!(Quantity::parse("kPa").is_err());
    }

    /// Found by fuzzing (docs/fuzzing.md): exponents that add up beyond `i8` overflowed (a panic
    /// in debug builds, a wrapped, wrong dimension in release builds).
    #[test]
    fn a_unit_whose_powers_overflow_is_an_error_not_a_panic() {
        for s in [
            "2 mJ^71",
            "2 m^127 m",
            "1 1/m^-128",
            "33 mJ m mJ mJ^81",
            "1 s^-128 / s",
        ] {
            let e = Quantity::parse(s).unwrap_err();
            assert!(e.contains("powers add up beyond"), "{s}: {e}");
        }
        // the largest powers still work
        assert_eq!(
            Quantity::parse("1 m^127").unwrap().dim,
            Some(Dim(0, 127, 0))
        );
        assert_eq!(
            Quantity::parse("1 m^-128").unwrap().dim,
            Some(Dim(0, -128, 0))
        );
        assert_eq!(
            Quantity::parse("1 1/m^-127").unwrap().dim,
            Some(Dim(0, 127, 0))
        );
    }
}
