//! Where a scene's error messages point: the scene file, and the line of the scene text where
//! the offending value appears. Every check of scene building reports through [`Locate::err`].

use std::fmt::Display;
use std::path::Path;

/// A scene file and its text, for error messages.
#[derive(Clone, Copy)]
pub(crate) struct Locate<'a> {
    /// The scene file.
    pub path: &'a Path,
    /// Its text.
    pub src: &'a str,
}

impl Locate<'_> {
    /// `FILE:LINE: `key`: msg`, with the line of the first occurrence of `needle` in the text,
    /// or `FILE: `key`: msg` where there is no needle or it does not occur.
    pub(crate) fn err(&self, key: &str, needle: Option<&str>, msg: &dyn Display) -> String {
        format!("{}: `{}`: {}", self.place(needle), key, msg)
    }

    /// `FILE:LINE` of the first occurrence of `needle` in the text, or `FILE`.
    pub(crate) fn place(&self, needle: Option<&str>) -> String {
        let line = needle.and_then(|n| self.src.lines().position(|l| l.contains(n)).map(|i| i + 1));
        match line {
            Some(l) => format!("{}:{}", self.path.display(), l),
            None => self.path.display().to_string(),
        }
    }
}

/// An axis name (`x`, `y`, `z`) as its index.
pub(crate) fn axis(s: &str) -> Option<usize> {
    match s {
        "x" => Some(0),
        "y" => Some(1),
        "z" => Some(2),
        _ => None,
    }
}
