//! `Dataset::select_training`: fewer training samples, the test samples untouched.

use surrogate::synthetic::make_synthetic_dataset;
use surrogate::Split;

/// The first 5 training locations at every 10 ms: 5 x 3 training rows (stamps 0, 10, 20 ms of
/// 0..25 ms), the 3 x 6 test rows untouched; selections that keep nothing or ask for more
/// locations than there are are errors.
#[test]
fn select_training_keeps_the_first_locations_and_stamps() {
    let d = make_synthetic_dataset(4);
    let s = d.select_training(Some(5), Some(0.010)).unwrap();
    let train = s.rows_with_split(Split::Train);
    assert_eq!(train.len(), 15);
    assert!(train.iter().all(|&i| s.location[i] < 5));
    assert_eq!(s.rows_with_split(Split::Test).len(), 18);
    assert!(d.select_training(Some(26), None).is_err());
    assert!(d.select_training(None, Some(-1.0)).is_err());
    assert_eq!(d.select_training(None, None).unwrap(), d);
}

/// Leaving training locations out drops their samples and only theirs (the test samples are
/// untouched); a label that is not a training location, or leaving every one out, is an error
/// that names it.
#[test]
fn training_locations_are_left_out_by_label() {
    let d = make_synthetic_dataset(4);
    let order = d.training_location_order();
    let (first, second) = (d.location_label(order[0]), d.location_label(order[1]));
    let s = d
        .without_training_locations(&[first.clone(), second])
        .unwrap();
    let per_location = d.rows_with_split(Split::Train).len() / order.len();
    assert_eq!(
        s.rows_with_split(Split::Train).len(),
        d.rows_with_split(Split::Train).len() - 2 * per_location
    );
    assert!(s
        .rows_with_split(Split::Train)
        .iter()
        .all(|&i| s.location[i] != order[0] && s.location[i] != order[1]));
    assert_eq!(
        s.rows_with_split(Split::Test).len(),
        d.rows_with_split(Split::Test).len()
    );
    let test_label = d.location_label(d.location[d.rows_with_split(Split::Test)[0]]);
    let err = d
        .without_training_locations(&[test_label.clone()])
        .unwrap_err()
        .to_string();
    assert!(
        err.contains(&format!("`{test_label}` is not a training location")),
        "{err}"
    );
    let all: Vec<String> = order.iter().map(|&l| d.location_label(l)).collect();
    let err = d.without_training_locations(&all).unwrap_err().to_string();
    assert!(err.contains("keeps no training sample"), "{err}");
    // after the first 3 locations, the 4th is not in the selection to leave out
    let first3 = d.select_training(Some(3), None).unwrap();
    assert!(first3
        .without_training_locations(&[d.location_label(order[3])])
        .is_err());
    assert!(first3.without_training_locations(&[first]).is_ok());
}

/// A label given twice, or an empty one, is refused by name.
#[test]
fn leave_out_refuses_a_label_twice_or_empty() {
    let d = make_synthetic_dataset(4);
    let first = d.location_label(d.training_location_order()[0]);
    let err = d
        .without_training_locations(&[first.clone(), first.clone()])
        .unwrap_err()
        .to_string();
    assert!(err.contains(&format!("`{first}` is given twice")), "{err}");
    let err = d
        .without_training_locations(&[String::new()])
        .unwrap_err()
        .to_string();
    assert!(err.contains("an empty label"), "{err}");
}
