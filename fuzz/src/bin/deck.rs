//! afl.rs target `deck`: [`palpa_fuzz::deck`]. Built by `cargo afl build` it is the fuzz
//! target; a plain build replays the files named on its command line.

#[cfg(fuzzing)]
fn main() {
    afl::fuzz!(|data: &[u8]| palpa_fuzz::deck(data));
}

#[cfg(not(fuzzing))]
fn main() {
    palpa_fuzz::replay_args("deck", palpa_fuzz::deck);
}
