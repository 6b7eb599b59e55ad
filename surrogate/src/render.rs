//! The stress picture as a PNG: the ROI's maximum principal stress in plan view, as the live
//! view of `palpa serve` draws it (`palpa predict --png`, `palpa palpate`'s
//! `roi_stress_map.png`).
//!
//! What it shows, in the phantom's plan frame (x towards the patient's left, to the right of the
//! picture; y cranial, up), when the model's plan geometry ([`ViewGeometry`]) is known: the
//! torso, the reduced model's box, the anterior ribs and the liver's outline, the ROI elements
//! as filled cells (their plan footprints) coloured by the stress on a [`ColourScale`] with a
//! colour bar in kPa, the two fingers where they press, the training locations' hull (dotted)
//! when given, a title stating x, y, the force and the time, and the reasons the input lies
//! outside what the model was trained on, in red. Where elements overlap in plan (the ROI is a
//! few elements deep), the cells are drawn in order of rising stress, so a point of the picture
//! shows the largest stress beneath it. Without the geometry, each ROI element is a square
//! around its centroid, as wide as the median distance to its nearest neighbour in plan.
//!
//! Text uses built-in bitmap glyphs ([`crate::glyphs`]), so the picture is complete on a
//! machine without fonts. The file is written atomically.

use crate::colour::ColourScale;
use crate::dataset::write_atomic;
use crate::error::{Error, Result};
use crate::glyphs;
use crate::view::{bounds, Fingers, Ring, ViewGeometry};
use ndarray::ArrayView2;
use plotters::prelude::*;
use serde::Serialize;
use std::io::Write;
use std::path::Path;

/// Image size in pixels.
pub const SIZE: (u32, u32) = (1000, 760);
/// The map's rectangle in the image: left, top, width, height (px).
const MAP: (i32, i32, i32, i32) = (80, 116, 760, 604);

/// The colours of the picture's outlines (RGB), shared with the live page so both draw alike.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Palette {
    /// Outside the body.
    pub background: [u8; 3],
    /// The torso's plan area.
    pub torso: [u8; 3],
    /// The reduced model's box (dotted).
    pub model_box: [u8; 3],
    /// Rib fill.
    pub rib_fill: [u8; 3],
    /// Rib outline.
    pub rib_line: [u8; 3],
    /// Liver fill.
    pub liver_fill: [u8; 3],
    /// Liver outline.
    pub liver_line: [u8; 3],
    /// Training hull (dotted).
    pub hull: [u8; 3],
    /// Fingers.
    pub fingers: [u8; 3],
    /// Warnings.
    pub warning: [u8; 3],
    /// Text and frame.
    pub text: [u8; 3],
}

/// The picture's palette.
pub const PALETTE: Palette = Palette {
    background: [255, 255, 255],
    torso: [242, 238, 232],
    model_box: [160, 160, 160],
    rib_fill: [208, 208, 204],
    rib_line: [130, 130, 126],
    liver_fill: [247, 226, 214],
    liver_line: [140, 70, 40],
    hull: [80, 80, 170],
    fingers: [20, 20, 20],
    warning: [200, 0, 0],
    text: [0, 0, 0],
};

/// Where the hand presses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hand {
    /// Position [m].
    pub x: f64,
    /// Position [m].
    pub y: f64,
    /// Force [N].
    pub force: f64,
}

/// Everything one picture shows.
#[derive(Clone, Debug)]
pub struct Picture<'a> {
    /// Stress of each ROI element [Pa], in the model's order.
    pub values: &'a [f64],
    /// ROI element centroids, R x 3 (or R x 2) [m]: the cells when `view` is `None`.
    pub centroids: ArrayView2<'a, f64>,
    /// The plan geometry, if known.
    pub view: Option<&'a ViewGeometry>,
    /// The colour scale.
    pub scale: ColourScale,
    /// The hand, if pressing.
    pub hand: Option<Hand>,
    /// The simulation or session time [s], if any.
    pub time_s: Option<f64>,
    /// The training locations' hull, if known.
    pub hull: Option<&'a [[f64; 2]]>,
    /// Second title line: what the values are.
    pub subtitle: String,
    /// Reasons the input lies outside the training domain (drawn in red).
    pub warnings: Vec<String>,
}

/// Renders `values` (one per ROI element, Pa) at the x-y projection of `centroids` (R x 3, m)
/// on the values' own colour scale, without outlines or hand, to the PNG file `path`.
pub fn render_map<'a>(
    centroids: ArrayView2<'a, f64>,
    values: &'a [f64],
    path: &Path,
) -> Result<()> {
    render_picture(
        &Picture {
            values,
            centroids,
            view: None,
            scale: ColourScale::of_values(values),
            hand: None,
            time_s: None,
            hull: None,
            subtitle: "ROI maximum principal stress".into(),
            warnings: Vec::new(),
        },
        path,
    )
}

/// The title line: x, y in mm, the force in N, the time in ms, as given.
pub fn title(hand: Option<Hand>, time_s: Option<f64>) -> String {
    let mut parts = Vec::new();
    if let Some(h) = hand {
        parts.push(format!("x {:.1} mm", h.x * 1e3));
        parts.push(format!("y {:.1} mm", h.y * 1e3));
        parts.push(format!("force {:.1} N", h.force));
    }
    if let Some(t) = time_s {
        parts.push(format!("t {:.1} ms", t * 1e3));
    }
    if parts.is_empty() {
        "no press".into()
    } else {
        parts.join("   ")
    }
}

/// The cells of a picture: the view's footprints, or squares around the centroids (R x 2 or
/// R x 3, m) as wide as the median nearest-neighbour distance in plan (1 to 10 mm).
pub fn roi_cells(view: Option<&ViewGeometry>, centroids: ArrayView2<f64>) -> Vec<Ring> {
    if let Some(v) = view {
        return v.roi_cells.clone();
    }
    let c: Vec<[f64; 2]> = centroids.rows().into_iter().map(|r| [r[0], r[1]]).collect();
    let mut nn: Vec<f64> = c
        .iter()
        .enumerate()
        .map(|(i, a)| {
            c.iter()
                .enumerate()
                .filter(|&(j, b)| j != i && (a[0] != b[0] || a[1] != b[1]))
                .map(|(_, b)| (a[0] - b[0]).hypot(a[1] - b[1]))
                .fold(f64::INFINITY, f64::min)
        })
        .filter(|d| d.is_finite())
        .collect();
    nn.sort_by(f64::total_cmp);
    let side = nn
        .get(nn.len() / 2)
        .copied()
        .unwrap_or(0.003)
        .clamp(0.001, 0.01);
    let h = side / 2.0;
    c.iter()
        .map(|q| {
            vec![
                [q[0] - h, q[1] - h],
                [q[0] + h, q[1] - h],
                [q[0] + h, q[1] + h],
                [q[0] - h, q[1] + h],
            ]
        })
        .collect()
}

fn cells(p: &Picture) -> Vec<Ring> {
    roi_cells(p.view, p.centroids)
}

/// The picture's extent in the plan frame (m): the liver, the cells, the reduced model's box
/// (so that some of the body's surroundings show), the training hull and `extra` points (the
/// fingers), with a 15 mm margin. The live page uses it too.
pub fn plan_extent(
    view: Option<&ViewGeometry>,
    cells: &[Ring],
    hull: Option<&[[f64; 2]]>,
    extra: &[[f64; 2]],
) -> ([f64; 2], [f64; 2]) {
    let mut pts: Vec<[f64; 2]> = hull.map(|h| h.to_vec()).unwrap_or_default();
    pts.extend_from_slice(extra);
    if let Some(v) = view {
        if let Some(b) = &v.model_box {
            pts.extend_from_slice(b);
        }
        pts.extend(v.liver.iter().flatten());
    }
    bounds(cells.iter().flatten().chain(pts.iter()), 0.015)
}

fn extent(p: &Picture, cells: &[Ring]) -> ([f64; 2], [f64; 2]) {
    let fingers = p.view.map(|v| v.fingers.clone()).unwrap_or_default();
    let extra: Vec<[f64; 2]> = p
        .hand
        .map(|h| fingers.centres(h.x, h.y).to_vec())
        .unwrap_or_default();
    plan_extent(p.view, cells, p.hull, &extra)
}

/// A world (m) to pixel map that keeps the aspect ratio, centred in a `w` x `h` rectangle.
#[derive(Clone, Copy, Debug)]
struct Transform {
    s: f64,
    ox: f64,
    oy: f64,
}

impl Transform {
    fn fit(lo: [f64; 2], hi: [f64; 2], w: i32, h: i32) -> Transform {
        let s = (w as f64 / (hi[0] - lo[0])).min(h as f64 / (hi[1] - lo[1]));
        let ox = (w as f64 - s * (hi[0] - lo[0])) / 2.0 - s * lo[0];
        let oy = (h as f64 + s * (hi[1] - lo[1])) / 2.0 + s * lo[1];
        Transform { s, ox, oy }
    }
    fn px(&self, p: [f64; 2]) -> (i32, i32) {
        (
            (self.ox + self.s * p[0]).round() as i32,
            (self.oy - self.s * p[1]).round() as i32,
        )
    }
}

fn rgb(c: [u8; 3]) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

/// Renders the picture to the PNG file `path` (atomically).
pub fn render_picture(p: &Picture, path: &Path) -> Result<()> {
    let r = p.values.len();
    if p.centroids.nrows() != r || p.centroids.ncols() < 2 {
        return Err(Error::invalid(
            "centroids",
            format!(
                "shape {:?} for {r} values (expected R x 3)",
                p.centroids.dim()
            ),
        ));
    }
    if r == 0 {
        return Err(Error::invalid("values", "nothing to draw"));
    }
    if let Some(i) = p.values.iter().position(|v| !v.is_finite()) {
        return Err(Error::invalid("values", format!("entry {i} is not finite")));
    }
    if let Some(v) = p.view {
        if v.roi_cells.len() != r {
            return Err(Error::invalid(
                "view",
                format!("{} ROI cells for {r} values", v.roi_cells.len()),
            ));
        }
    }
    let fail = |e: &dyn std::fmt::Display| Error::format(path, format!("rendering: {e}"));
    let cells = cells(p);
    let (lo, hi) = extent(p, &cells);
    let (mx, my, mw, mh) = MAP;
    let tf = Transform::fit(lo, hi, mw, mh);

    // the map, in its own buffer (what falls outside it is dropped)
    let mut map = vec![255u8; (mw * mh * 3) as usize];
    {
        let area = BitMapBackend::with_buffer(&mut map, (mw as u32, mh as u32)).into_drawing_area();
        draw_map(&area, p, &cells, tf).map_err(|e| fail(&e))?;
        area.present().map_err(|e| fail(&e))?;
    }

    let (w, h) = SIZE;
    let mut image = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut image, SIZE).into_drawing_area();
        root.fill(&rgb(PALETTE.background)).map_err(|e| fail(&e))?;
        root.present().map_err(|e| fail(&e))?;
    }
    for row in 0..mh {
        let src = (row * mw * 3) as usize;
        let dst = (((my + row) * w as i32 + mx) * 3) as usize;
        image[dst..dst + (mw * 3) as usize].copy_from_slice(&map[src..src + (mw * 3) as usize]);
    }
    {
        let root = BitMapBackend::with_buffer(&mut image, SIZE).into_drawing_area();
        draw_frame(&root, p, lo, hi, tf).map_err(|e| fail(&e))?;
        root.present().map_err(|e| fail(&e))?;
    }
    write_png(&image, SIZE, path)
}

/// Writes an RGB buffer as a PNG, atomically.
fn write_png(rgb8: &[u8], (w, h): (u32, u32), path: &Path) -> Result<()> {
    let bytes = picture::encode_png(rgb8, w, h).map_err(|e| Error::format(path, e))?;
    write_atomic(path, |mut f| {
        f.write_all(&bytes).map_err(|e| Error::io(path, e))
    })
}

type Area<'b> = DrawingArea<BitMapBackend<'b>, plotters::coord::Shift>;
type DrawResult = std::result::Result<
    (),
    DrawingAreaErrorKind<<BitMapBackend<'static> as plotters::prelude::DrawingBackend>::ErrorType>,
>;

fn polygon(area: &Area, ring: &[[f64; 2]], tf: Transform, fill: RGBColor) -> DrawResult {
    let pts: Vec<(i32, i32)> = ring.iter().map(|&q| tf.px(q)).collect();
    area.draw(&Polygon::new(pts, fill.filled()))
}

fn outline(area: &Area, ring: &[[f64; 2]], tf: Transform, c: RGBColor, width: u32) -> DrawResult {
    let mut pts: Vec<(i32, i32)> = ring.iter().map(|&q| tf.px(q)).collect();
    if let Some(&first) = pts.first() {
        pts.push(first);
    }
    area.draw(&PathElement::new(pts, c.stroke_width(width)))
}

/// A closed polygon's outline as dots every `gap` px.
fn dotted(area: &Area, ring: &[[f64; 2]], tf: Transform, c: RGBColor, gap: f64) -> DrawResult {
    let n = ring.len();
    for k in 0..n {
        let (a, b) = (tf.px(ring[k]), tf.px(ring[(k + 1) % n]));
        let len = ((b.0 - a.0) as f64).hypot((b.1 - a.1) as f64);
        let steps = (len / gap).floor() as i32;
        for s in 0..steps.max(1) {
            let t = s as f64 / steps.max(1) as f64;
            let x = a.0 as f64 + t * (b.0 - a.0) as f64;
            let y = a.1 as f64 + t * (b.1 - a.1) as f64;
            area.draw(&Rectangle::new(
                [(x as i32, y as i32), (x as i32 + 1, y as i32 + 1)],
                c.filled(),
            ))?;
        }
    }
    Ok(())
}

fn draw_map(area: &Area, p: &Picture, cells: &[Ring], tf: Transform) -> DrawResult {
    area.fill(&rgb(PALETTE.background))?;
    if let Some(v) = p.view {
        polygon(area, &v.torso, tf, rgb(PALETTE.torso))?;
        for l in &v.liver {
            polygon(area, l, tf, rgb(PALETTE.liver_fill))?;
        }
        for rib in &v.ribs {
            polygon(area, rib, tf, rgb(PALETTE.rib_fill))?;
            outline(area, rib, tf, rgb(PALETTE.rib_line), 1)?;
        }
        if let Some(b) = &v.model_box {
            dotted(area, b, tf, rgb(PALETTE.model_box), 6.0)?;
        }
    }
    // cells in order of rising stress: where they overlap, the largest shows
    let mut order: Vec<usize> = (0..p.values.len()).collect();
    order.sort_by(|&a, &b| p.values[a].total_cmp(&p.values[b]));
    for &i in &order {
        polygon(area, &cells[i], tf, rgb(p.scale.rgb(p.values[i])))?;
    }
    if let Some(v) = p.view {
        for l in &v.liver {
            outline(area, l, tf, rgb(PALETTE.liver_line), 2)?;
        }
    }
    if let Some(h) = p.hull {
        dotted(area, h, tf, rgb(PALETTE.hull), 4.0)?;
    }
    if let Some(hand) = p.hand {
        let f: Fingers = p.view.map(|v| v.fingers.clone()).unwrap_or_default();
        let radius = (f.diameter_m / 2.0 * tf.s).round() as i32;
        let c = rgb(PALETTE.fingers);
        for q in f.centres(hand.x, hand.y) {
            area.draw(&Circle::new(tf.px(q), radius, c.stroke_width(2)))?;
        }
        let (cx, cy) = tf.px([hand.x, hand.y]);
        area.draw(&PathElement::new(
            vec![(cx - 5, cy), (cx + 5, cy)],
            c.stroke_width(1),
        ))?;
        area.draw(&PathElement::new(
            vec![(cx, cy - 5), (cx, cy + 5)],
            c.stroke_width(1),
        ))?;
    }
    Ok(())
}

fn text(area: &Area, s: &str, x: i32, y: i32, scale: i32, c: [u8; 3]) -> DrawResult {
    let colour = rgb(c);
    let mut res = Ok(());
    glyphs::for_each_pixel(s, x, y, scale, |px, py| {
        if res.is_ok() {
            res = area.draw_pixel((px, py), &colour);
        }
    });
    res
}

/// A tick step (m) that gives 4 to 10 ticks over `span`.
fn tick_step(span: f64) -> f64 {
    [0.005, 0.01, 0.02, 0.025, 0.05, 0.1, 0.2]
        .into_iter()
        .find(|s| span / s <= 10.0)
        .unwrap_or(0.5)
}

fn draw_frame(root: &Area, p: &Picture, lo: [f64; 2], hi: [f64; 2], tf: Transform) -> DrawResult {
    let (mx, my, mw, mh) = MAP;
    let black = rgb(PALETTE.text);
    text(root, &title(p.hand, p.time_s), 20, 12, 2, PALETTE.text)?;
    text(root, &p.subtitle, 20, 36, 1, PALETTE.text)?;
    for (k, w) in p.warnings.iter().take(4).enumerate() {
        text(
            root,
            &format!("! {w}"),
            20,
            50 + 11 * k as i32,
            1,
            PALETTE.warning,
        )?;
    }
    root.draw(&Rectangle::new(
        [(mx - 1, my - 1), (mx + mw, my + mh)],
        black.stroke_width(1),
    ))?;
    if !p.warnings.is_empty() {
        root.draw(&Rectangle::new(
            [(mx - 4, my - 4), (mx + mw + 3, my + mh + 3)],
            rgb(PALETTE.warning).stroke_width(3),
        ))?;
    }
    // ticks in mm along the bottom (x) and the left (y)
    let step = tick_step((hi[0] - lo[0]).max(hi[1] - lo[1]));
    let mut v = (lo[0] / step).ceil() * step;
    while v <= hi[0] {
        let (px, _) = tf.px([v, 0.0]);
        if (0..mw).contains(&px) {
            let x = mx + px;
            root.draw(&PathElement::new(
                vec![(x, my + mh), (x, my + mh + 5)],
                black.stroke_width(1),
            ))?;
            let label = format!("{:.0}", v * 1e3);
            text(
                root,
                &label,
                x - glyphs::text_width(&label, 1) / 2,
                my + mh + 8,
                1,
                PALETTE.text,
            )?;
        }
        v += step;
    }
    let mut v = (lo[1] / step).ceil() * step;
    while v <= hi[1] {
        let (_, py) = tf.px([0.0, v]);
        if (0..mh).contains(&py) {
            let y = my + py;
            root.draw(&PathElement::new(
                vec![(mx - 6, y), (mx - 1, y)],
                black.stroke_width(1),
            ))?;
            let label = format!("{:.0}", v * 1e3);
            text(
                root,
                &label,
                mx - 9 - glyphs::text_width(&label, 1),
                y - 4,
                1,
                PALETTE.text,
            )?;
        }
        v += step;
    }
    text(
        root,
        "x [mm], towards the patient's left",
        mx + mw / 2 - 136,
        my + mh + 24,
        1,
        PALETTE.text,
    )?;
    text(root, "y [mm], cranial", 8, my - 14, 1, PALETTE.text)?;

    // colour bar
    let (bx, by, bw, bh) = (875, 146, 30, 560);
    text(root, "kPa", bx, by - 26, 2, PALETTE.text)?;
    for k in 0..bh {
        let t = 1.0 - k as f64 / (bh - 1) as f64;
        let val = p.scale.lo + t * (p.scale.hi - p.scale.lo);
        root.draw(&Rectangle::new(
            [(bx, by + k), (bx + bw, by + k + 1)],
            rgb(p.scale.rgb(val)).filled(),
        ))?;
    }
    root.draw(&Rectangle::new(
        [(bx, by), (bx + bw, by + bh)],
        black.stroke_width(1),
    ))?;
    let mut marks: Vec<f64> = (0..=5)
        .map(|k| p.scale.lo + (p.scale.hi - p.scale.lo) * k as f64 / 5.0)
        .collect();
    if p.scale.lo < 0.0 {
        marks.push(0.0);
    }
    for val in marks {
        let t = (val - p.scale.lo) / (p.scale.hi - p.scale.lo);
        let y = by + ((1.0 - t) * (bh - 1) as f64).round() as i32;
        root.draw(&PathElement::new(
            vec![(bx + bw, y), (bx + bw + 4, y)],
            black.stroke_width(1),
        ))?;
        text(
            root,
            &format!("{:.1}", val / 1e3),
            bx + bw + 7,
            y - 4,
            1,
            PALETTE.text,
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::Array2;

    /// Reads a PNG back as RGB.
    fn read_png(path: &Path) -> (Vec<u8>, u32, u32) {
        let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
        let mut r = dec.read_info().unwrap();
        let mut buf = vec![0; r.output_buffer_size().unwrap()];
        let info = r.next_frame(&mut buf).unwrap();
        buf.truncate(info.buffer_size());
        (buf, info.width, info.height)
    }

    /// Two far-apart square cells of 0 and 10 kPa on a 0..10 kPa scale: the pixel at each
    /// cell's centre has the scale's colour of its value, and the title is drawn (ink in the
    /// title band).
    #[test]
    fn cells_take_the_scale_colours() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.png");
        let c = Array2::from_shape_vec((2, 3), vec![0.0, 0.0, 0.0, 0.05, 0.03, 0.0]).unwrap();
        let values = [0.0, 10.0e3];
        let scale = ColourScale::over(0.0, 10.0e3);
        let pic = Picture {
            values: &values,
            centroids: c.view(),
            view: None,
            scale,
            hand: Some(Hand {
                x: 0.02,
                y: 0.01,
                force: 12.5,
            }),
            time_s: Some(0.025),
            hull: None,
            subtitle: "test".into(),
            warnings: vec!["outside".into()],
        };
        render_picture(&pic, &path).unwrap();
        let (img, w, h) = read_png(&path);
        assert_eq!((w, h), SIZE);
        let cells = cells(&pic);
        let (lo, hi) = extent(&pic, &cells);
        let tf = Transform::fit(lo, hi, MAP.2, MAP.3);
        for (k, v) in values.iter().enumerate() {
            let (px, py) = tf.px([c[(k, 0)], c[(k, 1)]]);
            let at = (((MAP.1 + py) * w as i32 + MAP.0 + px) * 3) as usize;
            assert_eq!(&img[at..at + 3], &scale.rgb(*v), "cell {k}");
        }
        let title_ink = (12..28)
            .flat_map(|y| (20..400).map(move |x| (y * w as usize + x) * 3))
            .filter(|&i| img[i] < 100)
            .count();
        assert!(title_ink > 200, "title pixels: {title_ink}");
        assert_eq!(
            title(pic.hand, pic.time_s),
            "x 20.0 mm   y 10.0 mm   force 12.5 N   t 25.0 ms"
        );
    }

    #[test]
    fn bad_input_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.png");
        let c = Array2::<f64>::zeros((2, 3));
        let e = render_map(c.view(), &[1.0], &path).unwrap_err();
        assert!(e.to_string().contains("centroids"), "{e}");
        let e = render_map(c.view(), &[1.0, f64::NAN], &path).unwrap_err();
        assert!(e.to_string().contains("not finite"), "{e}");
        assert!(!path.exists(), "no file is left behind");
    }
}
