//! Train or test: the split of a location, and of each of its samples in a dataset, where
//! `dataset.npz`'s `split` array codes it 0 (train) or 1 (test).

use serde::{Deserialize, Serialize};

/// Training or held-out (test) location or sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Split {
    /// Used for training (dataset split 0).
    Train,
    /// Held out (dataset split 1).
    Test,
}

impl Split {
    /// The dataset's code: 0 for train, 1 for test.
    pub fn code(self) -> u8 {
        match self {
            Split::Train => 0,
            Split::Test => 1,
        }
    }

    /// The split of a dataset code, `None` for any other value.
    pub fn from_code(c: u8) -> Option<Split> {
        match c {
            0 => Some(Split::Train),
            1 => Some(Split::Test),
            _ => None,
        }
    }

    /// "train" or "test".
    pub fn name(self) -> &'static str {
        match self {
            Split::Train => "train",
            Split::Test => "test",
        }
    }
}
