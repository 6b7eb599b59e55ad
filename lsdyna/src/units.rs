//! The unit system of a deck. LS-DYNA decks carry no units: every number is in one consistent
//! system of mass, length and time, and forces, stresses and densities follow from it
//! (kg-mm-ms: forces in kN, stresses in GPa, densities in kg/mm^3). palpa works in SI, so a deck
//! is read in the system the user names (`--units kg-mm-ms`) or its `*CONTROL_UNITS` states.
//!
//! A quantity of dimension `M^a L^b T^c` is converted with the factor `m^a l^b t^c` (`m`, `l`,
//! `t`: the system's mass, length and time units in kg, m, s). For metric systems that factor is
//! a power of ten, `10^k`, and the conversion is one correctly rounded operation, `v * 10^k` for
//! `k >= 0` and `v / 10^-k` for `k < 0` (both `10^k` and `10^-k` are exact in binary for
//! `|k| <= 22`); the writer (`crate::export`) relies on that to choose decimal strings that read
//! back to the very same binary number.

use material::quantity::{Dim, Quantity};

/// A consistent unit system: the sizes of its mass, length and time units in SI.
#[derive(Clone, Debug, PartialEq)]
pub struct Units {
    /// Mass unit (kg).
    pub mass: f64,
    /// Length unit (m).
    pub length: f64,
    /// Time unit (s).
    pub time: f64,
    /// Base-ten exponents of the three units, when each is a power of ten.
    pow10: Option<[i32; 3]>,
    /// The system's name, e.g. `kg-mm-ms`.
    pub name: String,
}

/// The systems the error message offers.
pub const EXAMPLES: &str = "kg-mm-ms, t-mm-s, kg-m-s, g-mm-ms, g-cm-us";

fn pow10_of(x: f64) -> Option<i32> {
    let k = x.log10().round() as i32;
    (k.abs() <= 22 && 10f64.powi(k) == x).then_some(k)
}

impl Units {
    /// SI itself (kg-m-s).
    pub fn si() -> Units {
        Units::new(1.0, 1.0, 1.0, "kg-m-s")
    }

    fn new(mass: f64, length: f64, time: f64, name: &str) -> Units {
        let pow10 = match (pow10_of(mass), pow10_of(length), pow10_of(time)) {
            (Some(a), Some(b), Some(c)) => Some([a, b, c]),
            _ => None,
        };
        Units {
            mass,
            length,
            time,
            pow10,
            name: name.to_string(),
        }
    }

    /// Parse `kg-mm-ms`, `t-mm-s`, `kg-m-s`, ... : one mass, one length and one time unit in any
    /// order, separated by `-`, `,`, `/` or spaces (units as in scene files: kg g mg t, m cm mm
    /// um, s ms us).
    pub fn parse(s: &str) -> Result<Units, String> {
        let (mut m, mut l, mut t) = (None, None, None);
        let toks: Vec<&str> = s
            .split(|c: char| c == '-' || c == ',' || c == '/' || c.is_whitespace())
            .filter(|t| !t.is_empty())
            .collect();
        for tok in &toks {
            let tok = match *tok {
                "tonne" | "ton" => "t",
                "sec" => "s",
                o => o,
            };
            let q = Quantity::parse(&format!("1 {tok}")).map_err(|_| {
                format!("`{s}`: `{tok}` is not a unit of mass, length or time (e.g. {EXAMPLES})")
            })?;
            let slot = match q.dim {
                Some(Dim::MASS) => &mut m,
                Some(Dim::LENGTH) => &mut l,
                Some(Dim::TIME) => &mut t,
                _ => {
                    return Err(format!(
                        "`{s}`: `{tok}` is not a unit of mass, length or time (e.g. {EXAMPLES})"
                    ))
                }
            };
            if slot.is_some() {
                return Err(format!(
                    "`{s}` names two units of the same kind (give one mass, one length and one time unit, e.g. {EXAMPLES})"
                ));
            }
            *slot = Some(q.si);
        }
        match (m, l, t) {
            (Some(m), Some(l), Some(t)) => Ok(Units::new(m, l, t, &toks.join("-"))),
            _ => Err(format!(
                "`{s}` must name one mass, one length and one time unit, e.g. {EXAMPLES}"
            )),
        }
    }

    /// The system `*CONTROL_UNITS` states: LENGTH (m, mm, cm, in, ft), TIME (sec, ms,
    /// micro_s), MASS (kg, g, mtrc_ton, lb, slug, slinch).
    pub fn from_control_units(length: &str, time: &str, mass: &str) -> Result<Units, String> {
        let l = match length.to_ascii_lowercase().as_str() {
            "m" => 1.0,
            "mm" => 1e-3,
            "cm" => 1e-2,
            "in" => 0.0254,
            "ft" => 0.3048,
            o => return Err(format!("LENGTH `{o}` is not one of m, mm, cm, in, ft")),
        };
        let t = match time.to_ascii_lowercase().as_str() {
            "sec" | "s" => 1.0,
            "ms" => 1e-3,
            "micro_s" | "us" => 1e-6,
            o => return Err(format!("TIME `{o}` is not one of sec, ms, micro_s")),
        };
        let m = match mass.to_ascii_lowercase().as_str() {
            "kg" => 1.0,
            "g" => 1e-3,
            "mtrc_ton" | "t" => 1e3,
            "lb" => 0.453_592_37,
            "slug" => 14.593_902_937_206_364,
            // 1 lbf s^2 / in = 0.45359237 * 9.80665 / 0.0254 kg
            "slinch" => 0.453_592_37 * 9.806_65 / 0.0254,
            o => {
                return Err(format!(
                    "MASS `{o}` is not one of kg, g, mtrc_ton, lb, slug, slinch"
                ))
            }
        };
        let name = format!(
            "{}-{}-{}",
            mass.to_ascii_lowercase(),
            length.to_ascii_lowercase(),
            time.to_ascii_lowercase()
        );
        Ok(Units::new(m, l, t, &name))
    }

    /// The `*CONTROL_UNITS` words of this system, when it has them (LENGTH, TIME, MASS).
    pub fn control_units_words(&self) -> Option<[&'static str; 3]> {
        let l = match self.pow10?[1] {
            0 => "m",
            -2 => "cm",
            -3 => "mm",
            _ => return None,
        };
        let t = match self.pow10?[2] {
            0 => "sec",
            -3 => "ms",
            -6 => "micro_s",
            _ => return None,
        };
        let m = match self.pow10?[0] {
            0 => "kg",
            -3 => "g",
            3 => "mtrc_ton",
            _ => return None,
        };
        Some([l, t, m])
    }

    /// Whether two systems are the same.
    pub fn same_as(&self, o: &Units) -> bool {
        self.mass == o.mass && self.length == o.length && self.time == o.time
    }

    /// The conversion of a quantity of dimension `d` to SI.
    pub fn factor(&self, d: Dim) -> Factor {
        match self.pow10 {
            Some([a, b, c]) => Factor::Pow10(a * d.0 as i32 + b * d.1 as i32 + c * d.2 as i32),
            None => Factor::Mul(
                self.mass.powi(d.0 as i32)
                    * self.length.powi(d.1 as i32)
                    * self.time.powi(d.2 as i32),
            ),
        }
    }

    /// `v` (in this system) in SI.
    pub fn to_si(&self, v: f64, d: Dim) -> f64 {
        self.factor(d).to_si(v)
    }

    /// `v` (SI) in this system, the nearest binary number (the writer searches around it for
    /// the one that converts back exactly).
    pub fn from_si(&self, v: f64, d: Dim) -> f64 {
        self.factor(d).from_si(v)
    }

    /// A deck number given as text, in SI. With a power-of-ten factor the power is added to
    /// the number's decimal exponent before it is parsed, so the decimal is rounded to binary
    /// once: the text the writer derives from an SI value ([`Units::si_text`]) reads back as
    /// exactly that value. `None` when the text is not a number.
    pub fn to_si_text(&self, s: &str, d: Dim) -> Option<f64> {
        let t = s.trim().replace(['d', 'D'], "e");
        if t.is_empty() {
            return Some(0.0);
        }
        match self.factor(d) {
            Factor::Pow10(k) => {
                let (m, e) = match t.find(['e', 'E']) {
                    Some(i) => (&t[..i], t[i + 1..].parse::<i32>().ok()?),
                    None => (t.as_str(), 0),
                };
                m.parse::<f64>().ok()?;
                format!("{m}e{}", e + k).parse::<f64>().ok()
            }
            Factor::Mul(f) => t.parse::<f64>().ok().map(|v| v * f),
        }
    }

    /// The shortest text of the SI value `v` in this system that [`Units::to_si_text`] reads
    /// back as exactly `v`, within `room` characters (plain, exponent, or integer mantissa
    /// with exponent); `None` when none fits or the factor is not a power of ten.
    pub fn si_text(&self, v: f64, d: Dim, room: usize) -> Option<String> {
        let Factor::Pow10(k) = self.factor(d) else {
            return None;
        };
        if v == 0.0 {
            return Some("0.0".into());
        }
        let sci = format!("{v:e}");
        let (m, e) = sci.split_once('e')?;
        let e: i32 = e.parse::<i32>().ok()? - k;
        let (sign, m) = m.strip_prefix('-').map_or(("", m), |r| ("-", r));
        let digits: String = m.chars().filter(|c| *c != '.').collect();
        let n = digits.len() as i32;
        let mut cands = vec![
            format!("{sign}{m}e{e}"),
            format!("{sign}{digits}e{}", e - (n - 1)),
        ];
        // Plain notation: the decimal point after `e + 1` digits.
        let point = e + 1;
        if (-6..=21).contains(&point) {
            let plain = if point <= 0 {
                format!("{sign}0.{}{digits}", "0".repeat((-point) as usize))
            } else if point >= n {
                format!("{sign}{digits}{}.", "0".repeat((point - n) as usize))
            } else {
                format!(
                    "{sign}{}.{}",
                    &digits[..point as usize],
                    &digits[point as usize..]
                )
            };
            cands.insert(0, plain);
        }
        cands
            .into_iter()
            .filter(|c| c.len() <= room && self.to_si_text(c, d) == Some(v))
            .min_by_key(|c| c.len())
    }

    /// The unit of dimension `d` in words, for comments (e.g. `GPa`, `kg/mm^3`, `mm/ms`).
    pub fn unit_name(&self, d: Dim) -> String {
        let parts: Vec<&str> = self.name.split('-').collect();
        let (m, l, t) = (parts[0], parts[1], parts[2]);
        let named = [
            (Dim::LENGTH, l.to_string()),
            (Dim::TIME, t.to_string()),
            (Dim::MASS, m.to_string()),
            (Dim::VELOCITY, format!("{l}/{t}")),
            (Dim::ACCELERATION, format!("{l}/{t}^2")),
            (Dim::DENSITY, format!("{m}/{l}^3")),
            (Dim::RATE, format!("1/{t}")),
            (Dim::NONE, "1".to_string()),
        ];
        if let Some((_, n)) = named.iter().find(|(dd, _)| *dd == d) {
            return n.clone();
        }
        let si_name = |d: Dim| match d {
            Dim::PRESSURE => Some(["Pa", "kPa", "MPa", "GPa"]),
            Dim::FORCE => Some(["N", "kN", "MN", "GN"]),
            Dim::ENERGY => Some(["J", "kJ", "MJ", "GJ"]),
            _ => None,
        };
        if let (Some(names), Factor::Pow10(k)) = (si_name(d), self.factor(d)) {
            if k >= 0 && k % 3 == 0 && k <= 9 {
                return names[(k / 3) as usize].to_string();
            }
        }
        format!("{m}^{} {l}^{} {t}^{}", d.0, d.1, d.2)
    }
}

/// A conversion to SI.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Factor {
    /// Times `10^k`.
    Pow10(i32),
    /// Times a factor that is not a power of ten.
    Mul(f64),
}

impl Factor {
    /// Deck value to SI (one correctly rounded operation for `Pow10`).
    pub fn to_si(self, v: f64) -> f64 {
        match self {
            Factor::Pow10(0) => v,
            Factor::Pow10(k) if k > 0 => v * 10f64.powi(k),
            Factor::Pow10(k) => v / 10f64.powi(-k),
            Factor::Mul(f) => v * f,
        }
    }

    /// SI to deck value (the inverse operation; not always an exact inverse).
    pub fn from_si(self, v: f64) -> f64 {
        match self {
            Factor::Pow10(0) => v,
            Factor::Pow10(k) if k > 0 => v / 10f64.powi(k),
            Factor::Pow10(k) => v * 10f64.powi(-k),
            Factor::Mul(f) => v / f,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn systems_parse_in_any_order_and_convert() {
        let u = Units::parse("kg-mm-ms").unwrap();
        assert_eq!(u.factor(Dim::PRESSURE), Factor::Pow10(9));
        assert_eq!(u.factor(Dim::DENSITY), Factor::Pow10(9));
        assert_eq!(u.factor(Dim::FORCE), Factor::Pow10(3));
        assert_eq!(u.factor(Dim::VELOCITY), Factor::Pow10(0));
        assert_eq!(u.to_si(15.0, Dim::LENGTH), 0.015);
        assert_eq!(u.unit_name(Dim::PRESSURE), "GPa");
        assert_eq!(u.unit_name(Dim::FORCE), "kN");
        let v = Units::parse("mm ms kg").unwrap();
        assert!(v.same_as(&u));
        let t = Units::parse("t-mm-s").unwrap();
        assert_eq!(t.factor(Dim::PRESSURE), Factor::Pow10(6));
        assert_eq!(t.unit_name(Dim::PRESSURE), "MPa");
        assert_eq!(t.unit_name(Dim::FORCE), "N");
        assert_eq!(t.to_si(1.06e-9, Dim::DENSITY), 1.06e-9 * 1e12);
        assert!(Units::parse("kg-mm").is_err());
        assert!(Units::parse("kg-mm-kPa").unwrap_err().contains("kPa"));
        assert!(Units::parse("kg-g-ms").unwrap_err().contains("two units"));
        let c = Units::from_control_units("mm", "ms", "kg").unwrap();
        assert!(c.same_as(&u));
        assert_eq!(c.control_units_words(), Some(["mm", "ms", "kg"]));
        // Text conversion is exact: any SI value's text in mm reads back to the same bits.
        for v in [
            0.12000014565012436,
            -8.000000025919015e-3,
            4.650668556969104e-18,
            0.06,
        ] {
            let t = u.si_text(v, Dim::LENGTH, 20).unwrap();
            assert_eq!(u.to_si_text(&t, Dim::LENGTH), Some(v), "{t}");
        }
        assert_eq!(
            u.si_text(0.12000014565012436, Dim::LENGTH, 20).unwrap(),
            "120.00014565012436"
        );
        assert_eq!(u.to_si_text("1.5d-3", Dim::LENGTH), Some(1.5e-6));
        let imp = Units::from_control_units("in", "sec", "slinch").unwrap();
        // slinch-in-s: a force unit of 1 lbf = 4.4482216152605 N
        assert!((imp.to_si(1.0, Dim::FORCE) - 4.448_221_615_260_5).abs() < 1e-12);
    }
}
