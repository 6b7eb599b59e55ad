//! Where two JSON values first part ([`first_difference`]): the message that refuses to mix two
//! campaign plans (`campaign.json`), and that says where a copied run's scene parts from the
//! palpation its plan gives it.

use serde_json::Value;

/// Where two JSON values (two campaign plans, two scenes) first differ, for the message that
/// refuses to mix them:
/// `plan.locations[26].surface_m[0]: -0.0705 there, -0.0725 here`. `None` when equal; an
/// integer and a float of the same value are equal (`25` and `25.0`), two integers only when
/// they are the same integer (beyond 2^53 as well).
pub fn first_difference(there: &Value, here: &Value, path: &str) -> Option<String> {
    let short = |v: &Value| {
        let s = v.to_string();
        if s.chars().count() > 60 {
            format!("{}...", s.chars().take(57).collect::<String>())
        } else {
            s
        }
    };
    match (there, here) {
        (Value::Object(a), Value::Object(b)) => {
            let mut keys: Vec<&String> = a.keys().chain(b.keys()).collect();
            keys.sort();
            keys.dedup();
            keys.into_iter().find_map(|k| {
                let (x, y) = (a.get(k), b.get(k));
                match (x, y) {
                    (Some(x), Some(y)) => first_difference(x, y, &format!("{path}.{k}")),
                    _ => Some(format!(
                        "{path}.{k}: {} there, {} here",
                        x.map_or("absent".into(), short),
                        y.map_or("absent".into(), short)
                    )),
                }
            })
        }
        (Value::Array(a), Value::Array(b)) if a.len() == b.len() => a
            .iter()
            .zip(b)
            .enumerate()
            .find_map(|(i, (x, y))| first_difference(x, y, &format!("{path}[{i}]"))),
        (Value::Array(a), Value::Array(b)) => Some(format!(
            "{path}: {} entries there, {} here",
            a.len(),
            b.len()
        )),
        // TOML and JSON tell `25` from `25.0`; a plan does not. Two integers are compared
        // exactly below (a seed beyond 2^53 is not rounded).
        (Value::Number(a), Value::Number(b))
            if (a.is_f64() || b.is_f64()) && a.as_f64() == b.as_f64() =>
        {
            None
        }
        _ if there != here => Some(format!(
            "{path}: {} there, {} here",
            short(there),
            short(here)
        )),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::first_difference;
    use serde_json::json;

    #[test]
    fn first_difference_names_the_path_and_both_values() {
        let there =
            json!({"runs": [1, 2], "locations": [{"label": "A", "surface_m": [-0.0705, 0.1785]}]});
        let mut here = there.clone();
        assert_eq!(first_difference(&there, &here, "plan"), None);
        here["locations"][0]["surface_m"][0] = json!(-0.0725);
        assert_eq!(
            first_difference(&there, &here, "plan").as_deref(),
            Some("plan.locations[0].surface_m[0]: -0.0705 there, -0.0725 here")
        );
        here["runs"] = json!([1, 2, 3]);
        here["title"] = json!("new");
        // keys in sorted order: locations, runs, title
        assert_eq!(
            first_difference(&there, &here, "plan").as_deref(),
            Some("plan.locations[0].surface_m[0]: -0.0705 there, -0.0725 here")
        );
        here["locations"] = there["locations"].clone();
        assert_eq!(
            first_difference(&there, &here, "plan").as_deref(),
            Some("plan.runs: 2 entries there, 3 here")
        );
        here["runs"] = json!([1.0, 2.0]);
        assert_eq!(
            first_difference(
                &json!([9_007_199_254_740_993u64]),
                &json!([9_007_199_254_740_992u64]),
                "seed"
            )
            .as_deref(),
            Some("seed[0]: 9007199254740993 there, 9007199254740992 here")
        );
        assert_eq!(
            first_difference(&there, &here, "plan").as_deref(),
            Some("plan.title: absent there, \"new\" here")
        );
    }
}
