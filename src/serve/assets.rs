//! The page, embedded in the binary so that the view works offline: `page/index.html`,
//! `page/view.js` (the drawing, the inputs and the latency figures), `page/style.css`.

/// `GET /`.
pub const INDEX_HTML: &str = include_str!("page/index.html");
/// `GET /view.js`.
pub const VIEW_JS: &str = include_str!("page/view.js");
/// `GET /style.css`.
pub const STYLE_CSS: &str = include_str!("page/style.css");
