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
