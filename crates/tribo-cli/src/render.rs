//! Pictures of a [`Frame`]: PNG, SVG and animated GIF.
//!
//! A [`Camera`] maps world coordinates (metres, y up) to pixels (y down).
//! Each picture is first described as a short list of pixel-space drawing
//! primitives; the same list is rasterised with `tiny-skia` (PNG, GIF) or
//! written out as SVG text, so every output format has the same look:
//! light paper background, a 1 m grid, shapes with dark outlines, hatched
//! static ground, contact points as blue (stick) or orange-red (slip) dots
//! with a normal tick, joint pivots as small rings, a time label, a legend and a
//! scale bar.

use std::borrow::Cow;
use std::collections::HashMap;
use std::fmt;
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path as FsPath;

use tiny_skia::{FillRule, LineCap, LineJoin, Mask, Paint, PathBuilder, Pixmap, Rect, Stroke, Transform};

use crate::frame::{DrawContact, DrawKind, DrawShape, Frame};

/// Colour of contact points that stick (static friction holds), `#2f6fdf`.
pub const STICK_COLOR: [u8; 3] = [0x2f, 0x6f, 0xdf];
/// Colour of contact points that slip, `#e8512a`.
pub const SLIP_COLOR: [u8; 3] = [0xe8, 0x51, 0x2a];

const BG: [u8; 4] = [0xf7, 0xf5, 0xf0, 255];
const GRID: [u8; 4] = [0xe6, 0xe1, 0xd5, 255];
const GRID_FINE: [u8; 4] = [0xef, 0xec, 0xe4, 255];
const GRID_AXIS: [u8; 4] = [0xd5, 0xcd, 0xbc, 255];
const OUTLINE: [u8; 4] = [0x2e, 0x2b, 0x27, 255];
const STATIC_FILL: [u8; 3] = [0xcf, 0xc3, 0xab];
const STATIC_HATCH: [u8; 4] = [0xa8, 0x98, 0x7b, 255];
const STATIC_OUTLINE: [u8; 4] = [0x5e, 0x52, 0x42, 255];
const TEXT: [u8; 4] = [0x26, 0x25, 0x23, 255];
const PANEL_FILL: [u8; 4] = [255, 255, 255, 210];
const PANEL_STROKE: [u8; 4] = [0xd2, 0xcb, 0xbc, 255];
const HALO: [u8; 4] = [255, 255, 255, 235];

/// Outline width of shapes [px].
const OUTLINE_WIDTH: f32 = 1.5;
/// Perpendicular distance between hatch lines of static shapes [px].
const HATCH_SPACING: f32 = 7.0;
/// Contact dot radius [px].
const CONTACT_RADIUS: f32 = 3.5;
/// Radius of a joint pivot's ring [px].
const JOINT_RADIUS: f32 = 3.0;
/// Pixels per metre from which contact and joint markers have their full size.
const MARKER_FULL_SCALE: f32 = 20.0;
/// Smallest marker size factor (pictures of large scenes).
const MARKER_MIN: f32 = 0.35;
/// Length of the contact normal tick [px].
const CONTACT_TICK: f32 = 14.0;
/// Distance of the overlay panels from the image border [px].
const EDGE: f32 = 8.0;
/// Geometry farther than this outside the image is clipped away [px].
const CLIP_MARGIN: f32 = 16.0;
/// The grid is drawn only when the view is narrower than this [m].
const GRID_MAX_VIEW: f32 = 60.0;

/// What can go wrong when writing a picture.
#[derive(Debug)]
pub enum RenderError {
    /// Reading or writing a file failed.
    Io {
        /// What was being done, e.g. "writing /tmp/a.png".
        context: String,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The PNG encoder failed.
    Png(String),
    /// The GIF encoder failed.
    Gif(String),
    /// The picture cannot be made (zero or too large size, no frames, ...).
    Invalid(String),
}

impl fmt::Display for RenderError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RenderError::Io { context, source } => write!(f, "{context}: {source}"),
            RenderError::Png(msg) => write!(f, "PNG encoding failed: {msg}"),
            RenderError::Gif(msg) => write!(f, "GIF encoding failed: {msg}"),
            RenderError::Invalid(msg) => write!(f, "cannot render picture: {msg}"),
        }
    }
}

impl std::error::Error for RenderError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            RenderError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

fn io_err(context: impl Into<String>) -> impl FnOnce(std::io::Error) -> RenderError {
    let context = context.into();
    move |source| RenderError::Io { context, source }
}

// ---------------------------------------------------------------------------
// Camera
// ---------------------------------------------------------------------------

/// Maps world coordinates [m] (y up) to pixel coordinates (y down) of a
/// picture of `width` × `height` pixels. Uniform scale, so shapes keep their
/// aspect ratio.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    width: u32,
    height: u32,
    /// World point [m] shown at the centre of the picture.
    center: [f32; 2],
    /// Pixels per metre.
    scale: f32,
}

/// An axis-aligned box in world coordinates; empty while `min > max`.
#[derive(Clone, Copy, Debug)]
struct Bounds {
    min: [f32; 2],
    max: [f32; 2],
}

impl Bounds {
    const EMPTY: Bounds = Bounds {
        min: [f32::INFINITY; 2],
        max: [f32::NEG_INFINITY; 2],
    };

    fn is_empty(&self) -> bool {
        !(self.min[0] <= self.max[0] && self.min[1] <= self.max[1])
    }

    fn add_disc(&mut self, p: [f32; 2], r: f32) {
        let r = if r.is_finite() { r.abs() } else { 0.0 };
        if p[0].is_finite() && p[1].is_finite() {
            self.min[0] = self.min[0].min(p[0] - r);
            self.min[1] = self.min[1].min(p[1] - r);
            self.max[0] = self.max[0].max(p[0] + r);
            self.max[1] = self.max[1].max(p[1] + r);
        }
    }

    fn add_shape(&mut self, shape: &DrawShape) {
        match &shape.kind {
            DrawKind::Circle { center, radius, .. } => self.add_disc(*center, *radius),
            DrawKind::Polygon { points, radius } => {
                for p in points {
                    self.add_disc(*p, *radius);
                }
            }
            DrawKind::Capsule { p1, p2, radius } => {
                self.add_disc(*p1, *radius);
                self.add_disc(*p2, *radius);
            }
            DrawKind::Segment { p1, p2, .. } => {
                self.add_disc(*p1, 0.0);
                self.add_disc(*p2, 0.0);
            }
        }
    }

    fn size(&self) -> [f32; 2] {
        [self.max[0] - self.min[0], self.max[1] - self.min[1]]
    }

    fn center(&self) -> [f32; 2] {
        [0.5 * (self.min[0] + self.max[0]), 0.5 * (self.min[1] + self.max[1])]
    }
}

/// Text scale factor of the 8×8 font for a picture size.
fn text_scale(width: u32, height: u32) -> u32 {
    if width >= 480 && height >= 240 {
        2
    } else {
        1
    }
}

/// Inner padding of overlay panels [px].
fn panel_pad(ts: u32) -> f32 {
    3.0 * ts as f32
}

/// Height of the band at the top kept free for the labels [px].
fn top_band(width: u32, height: u32) -> f32 {
    let ts = text_scale(width, height);
    EDGE + 8.0 * ts as f32 + 2.0 * panel_pad(ts) + 4.0
}

impl Camera {
    /// A camera showing `center` [m] in the middle of a `width` × `height`
    /// picture at `pixels_per_metre`. Zero sizes become 1 pixel; a
    /// non-finite or non-positive scale becomes 100 px/m; a non-finite
    /// centre becomes the origin.
    pub fn new(center: [f32; 2], pixels_per_metre: f32, width: u32, height: u32) -> Camera {
        let scale = if pixels_per_metre.is_finite() && pixels_per_metre > 0.0 {
            pixels_per_metre
        } else {
            100.0
        };
        let center = if center[0].is_finite() && center[1].is_finite() {
            center
        } else {
            [0.0, 0.0]
        };
        Camera {
            width: width.max(1),
            height: height.max(1),
            center,
            scale,
        }
    }

    /// A camera that shows every moving shape of all `frames`.
    ///
    /// The view is the bounding box of the dynamic (non-static) shapes over
    /// all frames, grown by a 25 % margin and made at least 2 m wide and
    /// tall; static geometry (ground) does not enlarge it and is only drawn
    /// where it falls inside, so a 100 m ground does not shrink a 1 m scene.
    /// Without dynamic shapes the static ones are fitted instead; with no
    /// shapes at all a 10 m wide default view around (0, 2) m is used. A
    /// strip at the top is left free for the time label and legend. Aspect
    /// ratio is kept, y points up; the result never contains NaN.
    pub fn fit(frames: &[Frame], width: u32, height: u32) -> Camera {
        let width = width.max(1);
        let height = height.max(1);
        let mut dynamic = Bounds::EMPTY;
        let mut fixed = Bounds::EMPTY;
        for frame in frames {
            for shape in &frame.shapes {
                if shape.is_static {
                    fixed.add_shape(shape);
                } else {
                    dynamic.add_shape(shape);
                }
            }
        }
        let content = if !dynamic.is_empty() {
            dynamic
        } else if !fixed.is_empty() {
            fixed
        } else {
            Bounds {
                min: [-5.0, -1.0],
                max: [5.0, 5.0],
            }
        };
        let size = content.size();
        let margin = 0.125 * size[0].max(size[1]);
        let view_w = (size[0] + 2.0 * margin).max(2.0);
        let view_h = (size[1] + 2.0 * margin).max(2.0);
        let center = content.center();

        let band = top_band(width, height);
        let avail_w = (width as f32 - 2.0 * EDGE).max(width as f32 * 0.5).max(1.0);
        let avail_h = (height as f32 - band - EDGE).max(height as f32 * 0.5).max(1.0);
        let scale = (avail_w / view_w).min(avail_h / view_h);
        let scale = if scale.is_finite() && scale > 0.0 {
            scale.clamp(1e-6, 1e6)
        } else {
            100.0
        };
        // The content is centred in the area below the label band.
        let area_mid_y = band + 0.5 * avail_h;
        let shift = (area_mid_y - 0.5 * height as f32) / scale;
        Camera::new([center[0], center[1] + shift], scale, width, height)
    }

    /// Picture width [px].
    #[cfg(test)]
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Picture height [px].
    #[cfg(test)]
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Pixels per metre.
    #[cfg(test)]
    pub fn pixels_per_metre(&self) -> f32 {
        self.scale
    }

    /// World point [m] shown at the centre of the picture.
    #[cfg(test)]
    pub fn center(&self) -> [f32; 2] {
        self.center
    }

    /// Pixel position of a world point [m].
    pub fn to_pixel(&self, p: [f32; 2]) -> [f32; 2] {
        [
            0.5 * self.width as f32 + (p[0] - self.center[0]) * self.scale,
            0.5 * self.height as f32 - (p[1] - self.center[1]) * self.scale,
        ]
    }

    /// World point [m] at a pixel position.
    pub fn to_world(&self, px: [f32; 2]) -> [f32; 2] {
        [
            self.center[0] + (px[0] - 0.5 * self.width as f32) / self.scale,
            self.center[1] - (px[1] - 0.5 * self.height as f32) / self.scale,
        ]
    }

    /// Width of the visible world [m].
    pub fn view_width(&self) -> f32 {
        self.width as f32 / self.scale
    }
}

// ---------------------------------------------------------------------------
// Display list
// ---------------------------------------------------------------------------

type Rgba = [u8; 4];

/// One pixel-space drawing primitive.
#[derive(Clone, Debug)]
enum Prim {
    /// Axis-aligned crisp rectangle (background, grid lines).
    Rect {
        x: f32,
        y: f32,
        w: f32,
        h: f32,
        color: Rgba,
    },
    /// Rounded semi-transparent box behind overlay text.
    Panel { x: f32, y: f32, w: f32, h: f32 },
    /// Anti-aliased line with round caps.
    Line {
        a: [f32; 2],
        b: [f32; 2],
        color: Rgba,
        width: f32,
    },
    /// Closed polygon (rounded outlines are sampled finely).
    Poly {
        pts: Vec<[f32; 2]>,
        fill: Rgba,
        hatch: bool,
        stroke: Rgba,
        sharp: bool,
    },
    /// Circle with optional fill, hatch and outline.
    Circle {
        c: [f32; 2],
        r: f32,
        fill: Option<Rgba>,
        hatch: bool,
        stroke: Option<(Rgba, f32)>,
    },
    /// Text in the 8×8 font; (x, y) is the top-left corner.
    Text {
        x: f32,
        y: f32,
        text: String,
        color: Rgba,
        scale: u32,
    },
}

fn rgb(c: [u8; 3]) -> Rgba {
    [c[0], c[1], c[2], 255]
}

fn mix(a: [u8; 3], b: [u8; 3], t: f32) -> [u8; 3] {
    let f = |x: u8, y: u8| (x as f32 + (y as f32 - x as f32) * t).round().clamp(0.0, 255.0) as u8;
    [f(a[0], b[0]), f(a[1], b[1]), f(a[2], b[2])]
}

fn desaturate(c: [u8; 3]) -> [u8; 3] {
    let l = (0.299 * c[0] as f32 + 0.587 * c[1] as f32 + 0.114 * c[2] as f32).round() as u8;
    let grey = mix(c, [l, l, l], 0.6);
    mix(grey, [BG[0], BG[1], BG[2]], 0.25)
}

fn finite2(p: [f32; 2]) -> bool {
    p[0].is_finite() && p[1].is_finite()
}

/// Appends arc points around `c` from angle `a0` over `sweep` [rad]
/// (pixel space, angles measured with the y-down axes), both ends included.
fn arc(out: &mut Vec<[f32; 2]>, c: [f32; 2], r: f32, a0: f32, sweep: f32) {
    let tol = 0.1_f32;
    let step = if r > tol {
        2.0 * (1.0 - tol / r).clamp(-1.0, 1.0).acos()
    } else {
        sweep.abs().max(0.1)
    };
    let step = step.max(1e-3);
    let n = ((sweep.abs() / step).ceil() as usize).clamp(1, 720);
    for i in 0..=n {
        let a = a0 + sweep * i as f32 / n as f32;
        out.push([c[0] + r * a.cos(), c[1] + r * a.sin()]);
    }
}

fn circle_points(c: [f32; 2], r: f32) -> Vec<[f32; 2]> {
    let mut pts = Vec::new();
    arc(&mut pts, c, r, 0.0, std::f32::consts::TAU);
    pts.pop();
    pts
}

fn capsule_points(p1: [f32; 2], p2: [f32; 2], r: f32) -> Vec<[f32; 2]> {
    let d = [p2[0] - p1[0], p2[1] - p1[1]];
    if d[0].hypot(d[1]) < 1e-4 {
        return circle_points(p1, r);
    }
    let theta = d[1].atan2(d[0]);
    let half = std::f32::consts::FRAC_PI_2;
    let mut pts = Vec::new();
    arc(&mut pts, p2, r, theta - half, std::f32::consts::PI);
    arc(&mut pts, p1, r, theta + half, std::f32::consts::PI);
    pts
}

/// Outline of a convex polygon grown by `r` (pixel space).
fn rounded_polygon_points(points: &[[f32; 2]], r: f32) -> Vec<[f32; 2]> {
    let mut v: Vec<[f32; 2]> = Vec::with_capacity(points.len());
    for p in points {
        if let Some(last) = v.last() {
            if (p[0] - last[0]).hypot(p[1] - last[1]) < 1e-4 {
                continue;
            }
        }
        v.push(*p);
    }
    while v.len() > 1 {
        let (first, last) = (v[0], v[v.len() - 1]);
        if (first[0] - last[0]).hypot(first[1] - last[1]) < 1e-4 {
            v.pop();
        } else {
            break;
        }
    }
    let n = v.len();
    if n == 0 {
        return Vec::new();
    }
    if n == 1 {
        return if r > 0.0 { circle_points(v[0], r) } else { Vec::new() };
    }
    let mut area2 = 0.0;
    for i in 0..n {
        let (a, b) = (v[i], v[(i + 1) % n]);
        area2 += a[0] * b[1] - b[0] * a[1];
    }
    let mut span = 0.0_f32;
    for a in &v {
        for b in &v {
            span = span.max((a[0] - b[0]).hypot(a[1] - b[1]));
        }
    }
    if n == 2 || area2.abs() < 1e-3 * span.max(1e-3) {
        // Degenerate (collinear): a capsule between the two farthest points.
        let (mut pa, mut pb, mut best) = (v[0], v[0], -1.0_f32);
        for a in &v {
            for b in &v {
                let d = (a[0] - b[0]).hypot(a[1] - b[1]);
                if d > best {
                    best = d;
                    pa = *a;
                    pb = *b;
                }
            }
        }
        return if r > 0.0 {
            capsule_points(pa, pb, r.max(0.5))
        } else {
            capsule_points(pa, pb, 0.75)
        };
    }
    if r <= 0.01 {
        return v;
    }
    let sgn = area2.signum();
    let normal = |a: [f32; 2], b: [f32; 2]| {
        let d = [b[0] - a[0], b[1] - a[1]];
        let len = d[0].hypot(d[1]).max(1e-12);
        [sgn * d[1] / len, -sgn * d[0] / len]
    };
    let mut out = Vec::new();
    for i in 0..n {
        let prev = v[(i + n - 1) % n];
        let cur = v[i];
        let next = v[(i + 1) % n];
        let n0 = normal(prev, cur);
        let n1 = normal(cur, next);
        let a0 = n0[1].atan2(n0[0]);
        let a1 = n1[1].atan2(n1[0]);
        let mut sweep = a1 - a0;
        while sweep > std::f32::consts::PI {
            sweep -= std::f32::consts::TAU;
        }
        while sweep <= -std::f32::consts::PI {
            sweep += std::f32::consts::TAU;
        }
        arc(&mut out, cur, r, a0, sweep);
    }
    out
}

/// Sutherland–Hodgman clip of a convex outline to an axis-aligned box.
fn clip_polygon(pts: Vec<[f32; 2]>, min: [f32; 2], max: [f32; 2]) -> Vec<[f32; 2]> {
    let inside_all = pts
        .iter()
        .all(|p| p[0] >= min[0] && p[0] <= max[0] && p[1] >= min[1] && p[1] <= max[1]);
    if inside_all {
        return pts;
    }
    let mut poly = pts;
    // (axis, bound, keep if coordinate >= bound when `lower`)
    let planes = [
        (0usize, min[0], true),
        (0, max[0], false),
        (1, min[1], true),
        (1, max[1], false),
    ];
    for (axis, bound, lower) in planes {
        if poly.is_empty() {
            break;
        }
        let inside = |p: &[f32; 2]| if lower { p[axis] >= bound } else { p[axis] <= bound };
        let mut out = Vec::with_capacity(poly.len() + 4);
        for i in 0..poly.len() {
            let cur = poly[i];
            let prev = poly[(i + poly.len() - 1) % poly.len()];
            let (ci, pi) = (inside(&cur), inside(&prev));
            if ci != pi {
                let denom = cur[axis] - prev[axis];
                let t = if denom.abs() > 1e-12 {
                    (bound - prev[axis]) / denom
                } else {
                    0.0
                };
                out.push([prev[0] + (cur[0] - prev[0]) * t, prev[1] + (cur[1] - prev[1]) * t]);
            }
            if ci {
                out.push(cur);
            }
        }
        poly = out;
    }
    poly
}

/// Liang–Barsky clip of a line to an axis-aligned box.
fn clip_line(a: [f32; 2], b: [f32; 2], min: [f32; 2], max: [f32; 2]) -> Option<([f32; 2], [f32; 2])> {
    let d = [b[0] - a[0], b[1] - a[1]];
    let (mut t0, mut t1) = (0.0_f32, 1.0_f32);
    for axis in 0..2 {
        for (p, q) in [(-d[axis], a[axis] - min[axis]), (d[axis], max[axis] - a[axis])] {
            if p.abs() < 1e-12 {
                if q < 0.0 {
                    return None;
                }
            } else {
                let t = q / p;
                if p < 0.0 {
                    t0 = t0.max(t);
                } else {
                    t1 = t1.min(t);
                }
            }
        }
    }
    if t0 > t1 {
        return None;
    }
    Some((
        [a[0] + d[0] * t0, a[1] + d[1] * t0],
        [a[0] + d[0] * t1, a[1] + d[1] * t1],
    ))
}

/// Scene builder: turns a frame into primitives.
struct Scene<'a> {
    cam: &'a Camera,
    prims: Vec<Prim>,
    clip_min: [f32; 2],
    clip_max: [f32; 2],
}

impl<'a> Scene<'a> {
    fn new(cam: &'a Camera) -> Self {
        Scene {
            cam,
            prims: Vec::new(),
            clip_min: [-CLIP_MARGIN, -CLIP_MARGIN],
            clip_max: [cam.width as f32 + CLIP_MARGIN, cam.height as f32 + CLIP_MARGIN],
        }
    }

    fn grid(&mut self) {
        let cam = self.cam;
        let (w, h) = (cam.width as f32, cam.height as f32);
        if cam.view_width() >= GRID_MAX_VIEW || cam.scale < 6.0 {
            return;
        }
        let lo = cam.to_world([0.0, h]);
        let hi = cam.to_world([w, 0.0]);
        // Fine 0.1 m lines when a metre is large on screen.
        if cam.scale >= 250.0 {
            self.grid_lines(lo, hi, 0.1, GRID_FINE, None);
        }
        self.grid_lines(lo, hi, 1.0, GRID, Some(GRID_AXIS));
    }

    fn grid_lines(&mut self, lo: [f32; 2], hi: [f32; 2], step: f32, color: Rgba, axis: Option<Rgba>) {
        let cam = self.cam;
        let (w, h) = (cam.width as f32, cam.height as f32);
        for dim in 0..2 {
            let first = (lo[dim] / step).ceil() as i64;
            let last = (hi[dim] / step).floor() as i64;
            if last - first > 2000 {
                continue;
            }
            for k in first..=last {
                let world = k as f32 * step;
                let color = match axis {
                    Some(a) if k == 0 => a,
                    _ => color,
                };
                if dim == 0 {
                    let x = cam.to_pixel([world, 0.0])[0].floor();
                    self.prims.push(Prim::Rect {
                        x,
                        y: 0.0,
                        w: 1.0,
                        h,
                        color,
                    });
                } else {
                    let y = cam.to_pixel([0.0, world])[1].floor();
                    self.prims.push(Prim::Rect {
                        x: 0.0,
                        y,
                        w,
                        h: 1.0,
                        color,
                    });
                }
            }
        }
    }

    fn shape(&mut self, shape: &DrawShape) {
        let cam = self.cam;
        let s = cam.scale;
        let (fill, stroke) = if shape.is_static {
            (rgb(mix(STATIC_FILL, shape.fill, 0.15)), STATIC_OUTLINE)
        } else if shape.asleep {
            (rgb(desaturate(shape.fill)), [0x55, 0x52, 0x4d, 255])
        } else {
            (rgb(shape.fill), OUTLINE)
        };
        let hatch = shape.is_static;
        match &shape.kind {
            DrawKind::Circle { center, radius, angle } => {
                if !finite2(*center) || !radius.is_finite() {
                    return;
                }
                let c = cam.to_pixel(*center);
                let r = (radius.abs() * s).max(1.0);
                let (w, h) = (cam.width as f32, cam.height as f32);
                if c[0] + r < self.clip_min[0]
                    || c[0] - r > self.clip_max[0]
                    || c[1] + r < self.clip_min[1]
                    || c[1] - r > self.clip_max[1]
                {
                    return;
                }
                if r > 4.0 * (w + h) {
                    let pts = clip_polygon(circle_points(c, r), self.clip_min, self.clip_max);
                    if pts.len() >= 3 {
                        self.prims.push(Prim::Poly {
                            pts,
                            fill,
                            hatch,
                            stroke,
                            sharp: false,
                        });
                    }
                } else {
                    self.prims.push(Prim::Circle {
                        c,
                        r,
                        fill: Some(fill),
                        hatch,
                        stroke: Some((stroke, OUTLINE_WIDTH)),
                    });
                }
                if !shape.is_static && r >= 4.0 && angle.is_finite() {
                    let tip = [c[0] + r * angle.cos(), c[1] - r * angle.sin()];
                    self.prims.push(Prim::Line {
                        a: c,
                        b: tip,
                        color: stroke,
                        width: OUTLINE_WIDTH,
                    });
                    self.prims.push(Prim::Circle {
                        c,
                        r: (0.08 * r).clamp(1.5, 3.0),
                        fill: Some(stroke),
                        hatch: false,
                        stroke: None,
                    });
                }
            }
            DrawKind::Polygon { points, radius } => {
                if points.iter().any(|p| !finite2(*p)) || !radius.is_finite() {
                    return;
                }
                let px: Vec<[f32; 2]> = points.iter().map(|p| cam.to_pixel(*p)).collect();
                let r = radius.abs() * s;
                let pts = clip_polygon(rounded_polygon_points(&px, r), self.clip_min, self.clip_max);
                if pts.len() >= 3 {
                    self.prims.push(Prim::Poly {
                        pts,
                        fill,
                        hatch,
                        stroke,
                        sharp: r <= 0.01,
                    });
                }
            }
            DrawKind::Capsule { p1, p2, radius } => {
                if !finite2(*p1) || !finite2(*p2) || !radius.is_finite() {
                    return;
                }
                let r = (radius.abs() * s).max(0.75);
                let pts = capsule_points(cam.to_pixel(*p1), cam.to_pixel(*p2), r);
                let pts = clip_polygon(pts, self.clip_min, self.clip_max);
                if pts.len() >= 3 {
                    self.prims.push(Prim::Poly {
                        pts,
                        fill,
                        hatch,
                        stroke,
                        sharp: false,
                    });
                }
            }
            DrawKind::Segment { p1, p2, back } => {
                if !finite2(*p1) || !finite2(*p2) {
                    return;
                }
                let (a, b) = (cam.to_pixel(*p1), cam.to_pixel(*p2));
                let Some((a, b)) = clip_line(a, b, self.clip_min, self.clip_max) else {
                    return;
                };
                if shape.is_static {
                    // Screen y points down: a world direction (x, y) is (x, −y) on screen.
                    self.ground_ticks(a, b, back.map(|d| [d[0], -d[1]]));
                }
                let color = if shape.is_static { STATIC_OUTLINE } else { OUTLINE };
                self.prims.push(Prim::Line {
                    a,
                    b,
                    color,
                    width: 3.0,
                });
            }
        }
    }

    /// Short slanted ticks under a ground segment (engineering ground symbol), or on the
    /// side `back` [screen direction] of a one-sided one.
    fn ground_ticks(&mut self, a: [f32; 2], b: [f32; 2], back: Option<[f32; 2]>) {
        let d = [b[0] - a[0], b[1] - a[1]];
        let len = d[0].hypot(d[1]);
        if len < 2.0 {
            return;
        }
        let u = [d[0] / len, d[1] / len];
        // Screen normal pointing up (negative y); ticks go to the other side.
        let mut n = [u[1], -u[0]];
        let flip = match back {
            Some(k) => n[0] * k[0] + n[1] * k[1] > 0.0,
            None => n[1] > 0.0 || (n[1] == 0.0 && n[0] < 0.0),
        };
        if flip {
            n = [-n[0], -n[1]];
        }
        let spacing = 9.0;
        let count = (len / spacing).floor() as usize;
        let start = 0.5 * (len - count as f32 * spacing);
        for i in 0..=count.min(4000) {
            let t = start + i as f32 * spacing;
            let p = [a[0] + u[0] * t, a[1] + u[1] * t];
            let q = [p[0] - n[0] * 7.0 - u[0] * 6.0, p[1] - n[1] * 7.0 - u[1] * 6.0];
            self.prims.push(Prim::Line {
                a: p,
                b: q,
                color: STATIC_HATCH,
                width: 1.2,
            });
        }
    }

    fn contact(&mut self, c: &DrawContact) {
        if !finite2(c.point) {
            return;
        }
        let p = self.cam.to_pixel(c.point);
        if p[0] < self.clip_min[0] || p[0] > self.clip_max[0] || p[1] < self.clip_min[1] || p[1] > self.clip_max[1] {
            return;
        }
        let color = rgb(if c.stick { STICK_COLOR } else { SLIP_COLOR });
        let k = self.marker_scale();
        let (radius, tick) = (CONTACT_RADIUS * k, CONTACT_TICK * k);
        let nl = c.normal[0].hypot(c.normal[1]);
        if nl.is_finite() && nl > 1e-6 {
            let n = [c.normal[0] / nl, -c.normal[1] / nl];
            let tip = [p[0] + n[0] * tick, p[1] + n[1] * tick];
            self.prims.push(Prim::Line {
                a: p,
                b: tip,
                color: HALO,
                width: 2.0 + 2.0 * k,
            });
            self.prims.push(Prim::Line {
                a: p,
                b: tip,
                color,
                width: 2.0 * k,
            });
        }
        self.prims.push(Prim::Circle {
            c: p,
            r: radius + 1.3 * k,
            fill: Some(HALO),
            hatch: false,
            stroke: None,
        });
        self.prims.push(Prim::Circle {
            c: p,
            r: radius,
            fill: Some(color),
            hatch: false,
            stroke: None,
        });
    }

    /// A joint pivot: a small white ring with a dark outline.
    /// Size factor of the contact and joint markers: smaller on small pictures (where the
    /// text shrinks too), and in pictures of large scenes, below
    /// [`MARKER_FULL_SCALE`] pixels per metre (down to [`MARKER_MIN`]), so markers of
    /// fixed pixel size do not bury the shapes (Box2D's rain: 250 m across, 3 px/m).
    fn marker_scale(&self) -> f32 {
        let text = if text_scale(self.cam.width, self.cam.height) >= 2 {
            1.0
        } else {
            0.7
        };
        text * (self.cam.scale / MARKER_FULL_SCALE).clamp(MARKER_MIN, 1.0)
    }

    fn joint(&mut self, at: [f32; 2]) {
        if !finite2(at) {
            return;
        }
        let p = self.cam.to_pixel(at);
        if p[0] < self.clip_min[0] || p[0] > self.clip_max[0] || p[1] < self.clip_min[1] || p[1] > self.clip_max[1] {
            return;
        }
        let k = self.marker_scale();
        self.prims.push(Prim::Circle {
            c: p,
            r: JOINT_RADIUS * k,
            fill: Some(HALO),
            hatch: false,
            stroke: Some((OUTLINE, 1.5 * k)),
        });
    }

    fn overlays(&mut self, time: f32) {
        let cam = self.cam;
        let (w, h) = (cam.width as f32, cam.height as f32);
        let ts = text_scale(cam.width, cam.height);
        let g = 8.0 * ts as f32; // glyph cell
        let pad = panel_pad(ts);

        // Time label, top-left.
        let label = time_label(time);
        let tw = label.len() as f32 * g;
        let time_right = EDGE + tw + 2.0 * pad;
        if time_right <= w && EDGE + g + 2.0 * pad <= h {
            self.prims.push(Prim::Panel {
                x: EDGE,
                y: EDGE,
                w: tw + 2.0 * pad,
                h: g + 2.0 * pad,
            });
            self.prims.push(Prim::Text {
                x: EDGE + pad,
                y: EDGE + pad,
                text: label,
                color: TEXT,
                scale: ts,
            });
        }

        // Legend, top-right: "● stick  ● slip".
        let u = ts as f32;
        let gap = 3.0 * u;
        let legend_w = g + gap + 5.0 * g + g + g + gap + 4.0 * g;
        let lx = w - EDGE - legend_w - 2.0 * pad;
        if lx >= time_right + 8.0 && EDGE + g + 2.0 * pad <= h {
            self.prims.push(Prim::Panel {
                x: lx,
                y: EDGE,
                w: legend_w + 2.0 * pad,
                h: g + 2.0 * pad,
            });
            let ty = EDGE + pad;
            let mut x = lx + pad;
            for (color, text) in [(STICK_COLOR, "stick"), (SLIP_COLOR, "slip")] {
                let c = [x + 0.5 * g, ty + 3.5 * u];
                self.prims.push(Prim::Circle {
                    c,
                    r: 3.6 * u,
                    fill: Some(rgb(color)),
                    hatch: false,
                    stroke: None,
                });
                x += g + gap;
                self.prims.push(Prim::Text {
                    x,
                    y: ty,
                    text: text.to_string(),
                    color: TEXT,
                    scale: ts,
                });
                x += text.len() as f32 * g + g;
            }
        }

        // Scale bar, bottom-left.
        let target = (0.14 * w).clamp(50.0, 160.0);
        let raw = target / cam.scale;
        if raw.is_finite() && raw > 0.0 {
            let pow = 10f32.powf(raw.log10().floor());
            let mut len_m = pow;
            for m in [1.0, 2.0, 5.0, 10.0] {
                if m * pow <= raw * 1.0001 {
                    len_m = m * pow;
                }
            }
            let len_px = len_m * cam.scale;
            let text = scale_label(len_m);
            let text_w = text.len() as f32 * g;
            let pw = len_px.max(text_w) + 2.0 * pad + 2.0;
            let tick = 3.0 * u;
            let ph = pad + g + 2.0 * u + 2.0 * tick + pad;
            let (px, py) = (EDGE, h - EDGE - ph);
            if len_px.is_finite() && px + pw <= w - EDGE && py >= top_band(cam.width, cam.height) {
                self.prims.push(Prim::Panel {
                    x: px,
                    y: py,
                    w: pw,
                    h: ph,
                });
                let x0 = px + pad + 1.0 + 0.5 * (pw - 2.0 * pad - 2.0 - len_px);
                let yb = py + pad + g + 2.0 * u + tick;
                let x1 = x0 + len_px;
                self.prims.push(Prim::Line {
                    a: [x0, yb],
                    b: [x1, yb],
                    color: TEXT,
                    width: 2.0,
                });
                self.prims.push(Prim::Line {
                    a: [x0, yb - tick],
                    b: [x0, yb + tick],
                    color: TEXT,
                    width: 1.5,
                });
                self.prims.push(Prim::Line {
                    a: [x1, yb - tick],
                    b: [x1, yb + tick],
                    color: TEXT,
                    width: 1.5,
                });
                let tx = px + 0.5 * (pw - text_w);
                self.prims.push(Prim::Text {
                    x: tx,
                    y: py + pad,
                    text,
                    color: TEXT,
                    scale: ts,
                });
            }
        }
    }
}

/// "t = 1.25 s".
fn time_label(time: f32) -> String {
    if time.is_finite() {
        format!("t = {time:.2} s")
    } else {
        "t = ? s".to_string()
    }
}

/// "1 m", "20 cm", "5 mm", "100 m", "2 km".
fn scale_label(len_m: f32) -> String {
    let fmt_num = |v: f32| {
        let r = v.round();
        if (v - r).abs() < 1e-3 * v.max(1.0) {
            format!("{r:.0}")
        } else {
            let s = format!("{v:.3}");
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        }
    };
    if len_m >= 1000.0 {
        format!("{} km", fmt_num(len_m / 1000.0))
    } else if len_m >= 1.0 {
        format!("{} m", fmt_num(len_m))
    } else if len_m >= 0.01 {
        format!("{} cm", fmt_num(len_m * 100.0))
    } else {
        format!("{} mm", fmt_num(len_m * 1000.0))
    }
}

/// The primitives of one picture, back to front.
fn build_scene(frame: &Frame, camera: &Camera) -> Vec<Prim> {
    let mut scene = Scene::new(camera);
    let (w, h) = (camera.width as f32, camera.height as f32);
    scene.prims.push(Prim::Rect {
        x: 0.0,
        y: 0.0,
        w,
        h,
        color: BG,
    });
    scene.grid();
    // Static shapes first so moving ones are never hidden behind ground.
    for shape in frame.shapes.iter().filter(|s| s.is_static) {
        scene.shape(shape);
    }
    for shape in frame.shapes.iter().filter(|s| !s.is_static) {
        scene.shape(shape);
    }
    for c in &frame.contacts {
        scene.contact(c);
    }
    for &j in &frame.joints {
        scene.joint(j);
    }
    scene.overlays(frame.time);
    scene.prims
}

// ---------------------------------------------------------------------------
// Raster back end (tiny-skia)
// ---------------------------------------------------------------------------

fn paint(color: Rgba, anti_alias: bool) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color_rgba8(color[0], color[1], color[2], color[3]);
    p.anti_alias = anti_alias;
    p
}

fn poly_path(pts: &[[f32; 2]]) -> Option<tiny_skia::Path> {
    let (first, rest) = pts.split_first()?;
    let mut pb = PathBuilder::new();
    pb.move_to(first[0], first[1]);
    for p in rest {
        pb.line_to(p[0], p[1]);
    }
    pb.close();
    pb.finish()
}

/// Diagonal hatch lines clipped to `path`.
/// Fills `path` (if `fill`), hatches it (if `hatch`), then strokes it (if `outline`).
fn raster_shape(
    pixmap: &mut Pixmap,
    path: &tiny_skia::Path,
    fill: Option<Rgba>,
    hatch: bool,
    outline: Option<(Rgba, Stroke)>,
) {
    let id = Transform::identity();
    if let Some(f) = fill {
        pixmap.fill_path(path, &paint(f, true), FillRule::Winding, id, None);
    }
    if hatch {
        raster_hatch(pixmap, path);
    }
    if let Some((color, st)) = outline {
        pixmap.stroke_path(path, &paint(color, true), &st, id, None);
    }
}

fn raster_hatch(pixmap: &mut Pixmap, path: &tiny_skia::Path) {
    let b = path.bounds();
    let (w, h) = (pixmap.width() as f32, pixmap.height() as f32);
    let (x0, y0) = (b.left().max(0.0), b.top().max(0.0));
    let (x1, y1) = (b.right().min(w), b.bottom().min(h));
    if x0 >= x1 || y0 >= y1 {
        return;
    }
    let Some(mut mask) = Mask::new(pixmap.width(), pixmap.height()) else {
        return;
    };
    mask.fill_path(path, FillRule::Winding, true, Transform::identity());
    // Lines x + y = c, c on a global lattice so patterns line up across shapes.
    let step = HATCH_SPACING * std::f32::consts::SQRT_2;
    let mut pb = PathBuilder::new();
    let mut c = ((x0 + y0) / step).floor() * step;
    while c <= x1 + y1 {
        pb.move_to(c - y1, y1);
        pb.line_to(c - y0, y0);
        c += step;
    }
    if let Some(lines) = pb.finish() {
        let stroke = Stroke {
            width: 1.0,
            ..Stroke::default()
        };
        pixmap.stroke_path(
            &lines,
            &paint(STATIC_HATCH, true),
            &stroke,
            Transform::identity(),
            Some(&mask),
        );
    }
}

fn raster_text(pixmap: &mut Pixmap, x: f32, y: f32, text: &str, color: Rgba, scale: u32) {
    use font8x8::UnicodeFonts as _;
    let s = scale.max(1) as f32;
    let p = paint(color, false);
    for (i, ch) in text.chars().enumerate() {
        let glyph = font8x8::BASIC_FONTS
            .get(ch)
            .or_else(|| font8x8::BASIC_FONTS.get('?'))
            .unwrap_or([0; 8]);
        let gx = (x + i as f32 * 8.0 * s).round();
        for (row, bits) in glyph.iter().enumerate() {
            let mut col = 0;
            while col < 8 {
                if bits & (1 << col) != 0 {
                    let start = col;
                    while col < 8 && bits & (1 << col) != 0 {
                        col += 1;
                    }
                    let rx = gx + start as f32 * s;
                    let ry = y.round() + row as f32 * s;
                    if let Some(r) = Rect::from_xywh(rx, ry, (col - start) as f32 * s, s) {
                        pixmap.fill_rect(r, &p, Transform::identity(), None);
                    }
                } else {
                    col += 1;
                }
            }
        }
    }
}

fn panel_points(x: f32, y: f32, w: f32, h: f32) -> Vec<[f32; 2]> {
    let r = 4.0_f32.min(0.5 * w).min(0.5 * h);
    let half = std::f32::consts::FRAC_PI_2;
    let mut pts = Vec::new();
    arc(&mut pts, [x + w - r, y + r], r, -half, half);
    arc(&mut pts, [x + w - r, y + h - r], r, 0.0, half);
    arc(&mut pts, [x + r, y + h - r], r, half, half);
    arc(&mut pts, [x + r, y + r], r, 2.0 * half, half);
    pts
}

fn rasterize(prims: &[Prim], width: u32, height: u32) -> Result<Pixmap, RenderError> {
    let mut pixmap = Pixmap::new(width, height)
        .ok_or_else(|| RenderError::Invalid(format!("unsupported picture size {width}x{height}")))?;
    let id = Transform::identity();
    for prim in prims {
        match prim {
            Prim::Rect { x, y, w, h, color } => {
                if let Some(r) = Rect::from_xywh(*x, *y, *w, *h) {
                    pixmap.fill_rect(r, &paint(*color, false), id, None);
                }
            }
            Prim::Panel { x, y, w, h } => {
                if let Some(path) = poly_path(&panel_points(*x, *y, *w, *h)) {
                    pixmap.fill_path(&path, &paint(PANEL_FILL, true), FillRule::Winding, id, None);
                    let stroke = Stroke {
                        width: 1.0,
                        ..Stroke::default()
                    };
                    pixmap.stroke_path(&path, &paint(PANEL_STROKE, true), &stroke, id, None);
                }
            }
            Prim::Line { a, b, color, width } => {
                let mut pb = PathBuilder::new();
                pb.move_to(a[0], a[1]);
                pb.line_to(b[0], b[1]);
                if let Some(path) = pb.finish() {
                    let stroke = Stroke {
                        width: *width,
                        line_cap: LineCap::Round,
                        ..Stroke::default()
                    };
                    pixmap.stroke_path(&path, &paint(*color, true), &stroke, id, None);
                }
            }
            Prim::Poly {
                pts,
                fill,
                hatch,
                stroke,
                sharp,
            } => {
                if let Some(path) = poly_path(pts) {
                    let join = if *sharp { LineJoin::Miter } else { LineJoin::Round };
                    let st = Stroke {
                        width: OUTLINE_WIDTH,
                        line_join: join,
                        ..Stroke::default()
                    };
                    raster_shape(&mut pixmap, &path, Some(*fill), *hatch, Some((*stroke, st)));
                }
            }
            Prim::Circle {
                c,
                r,
                fill,
                hatch,
                stroke,
            } => {
                if let Some(path) = PathBuilder::from_circle(c[0], c[1], *r) {
                    let outline = stroke.map(|(color, width)| {
                        let st = Stroke {
                            width,
                            ..Stroke::default()
                        };
                        (color, st)
                    });
                    raster_shape(&mut pixmap, &path, *fill, *hatch, outline);
                }
            }
            Prim::Text {
                x,
                y,
                text,
                color,
                scale,
            } => raster_text(&mut pixmap, *x, *y, text, *color, *scale),
        }
    }
    Ok(pixmap)
}

/// Draws one frame as seen by `camera` into a new RGBA pixmap of the
/// camera's size. This is the single drawing routine behind PNG and GIF.
pub fn render_rgba(frame: &Frame, camera: &Camera) -> Result<Pixmap, RenderError> {
    rasterize(&build_scene(frame, camera), camera.width, camera.height)
}

/// Encodes one frame as PNG bytes (e.g. for embedding in an HTML report as
/// a `data:image/png;base64,...` URL).
pub fn png_bytes(frame: &Frame, camera: &Camera) -> Result<Vec<u8>, RenderError> {
    let pixmap = render_rgba(frame, camera)?;
    pixmap.encode_png().map_err(|e| RenderError::Png(e.to_string()))
}

/// Writes one frame as a PNG file.
pub fn write_png(frame: &Frame, camera: &Camera, path: &FsPath) -> Result<(), RenderError> {
    let bytes = png_bytes(frame, camera)?;
    std::fs::write(path, bytes).map_err(io_err(format!("writing {}", path.display())))
}

// ---------------------------------------------------------------------------
// SVG back end
// ---------------------------------------------------------------------------

fn num(v: f32) -> String {
    let s = format!("{v:.2}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" {
        "0".to_string()
    } else {
        s
    }
}

fn hex(c: Rgba) -> String {
    format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
}

/// ` fill="#rrggbb"` plus ` fill-opacity` when translucent.
fn paint_attr(attr: &str, c: Rgba) -> String {
    if c[3] == 255 {
        format!(" {attr}=\"{}\"", hex(c))
    } else {
        format!(" {attr}=\"{}\" {attr}-opacity=\"{}\"", hex(c), num(c[3] as f32 / 255.0))
    }
}

fn xml_escape(s: &str) -> String {
    s.chars()
        .map(|c| match c {
            '&' => "&amp;".to_string(),
            '<' => "&lt;".to_string(),
            '>' => "&gt;".to_string(),
            '"' => "&quot;".to_string(),
            c => c.to_string(),
        })
        .collect()
}

fn points_attr(pts: &[[f32; 2]]) -> String {
    let mut s = String::with_capacity(pts.len() * 12);
    for (i, p) in pts.iter().enumerate() {
        if i > 0 {
            s.push(' ');
        }
        s.push_str(&num(p[0]));
        s.push(',');
        s.push_str(&num(p[1]));
    }
    s
}

/// The SVG document of one frame (pixel units, same look as the PNG).
fn svg_string(frame: &Frame, camera: &Camera) -> String {
    let prims = build_scene(frame, camera);
    let (w, h) = (camera.width, camera.height);
    let mut out = String::new();
    let _ = writeln!(
        out,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\">"
    );
    let _ = writeln!(out, "<title>{}</title>", time_label(frame.time));
    let s = HATCH_SPACING;
    let _ = writeln!(
        out,
        "<defs><pattern id=\"hatch\" width=\"{}\" height=\"{}\" patternUnits=\"userSpaceOnUse\" \
         patternTransform=\"rotate(45)\"><line x1=\"0\" y1=\"0\" x2=\"0\" y2=\"{}\" stroke=\"{}\" \
         stroke-width=\"2\"/></pattern></defs>",
        num(s),
        num(s),
        num(s),
        hex(STATIC_HATCH)
    );
    let mut in_grid = false;
    for prim in &prims {
        let is_rect = matches!(prim, Prim::Rect { .. });
        if is_rect && !in_grid {
            out.push_str("<g shape-rendering=\"crispEdges\">\n");
            in_grid = true;
        } else if !is_rect && in_grid {
            out.push_str("</g>\n");
            in_grid = false;
        }
        match prim {
            Prim::Rect { x, y, w, h, color } => {
                let _ = writeln!(
                    out,
                    "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"{}/>",
                    num(*x),
                    num(*y),
                    num(*w),
                    num(*h),
                    paint_attr("fill", *color)
                );
            }
            Prim::Panel { x, y, w, h } => {
                let _ = writeln!(
                    out,
                    "<rect class=\"panel\" x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" rx=\"4\"{}{}/>",
                    num(*x),
                    num(*y),
                    num(*w),
                    num(*h),
                    paint_attr("fill", PANEL_FILL),
                    paint_attr("stroke", PANEL_STROKE)
                );
            }
            Prim::Line { a, b, color, width } => {
                let _ = writeln!(
                    out,
                    "<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\"{} stroke-width=\"{}\" stroke-linecap=\"round\"/>",
                    num(a[0]),
                    num(a[1]),
                    num(b[0]),
                    num(b[1]),
                    paint_attr("stroke", *color),
                    num(*width)
                );
            }
            Prim::Poly {
                pts,
                fill,
                hatch,
                stroke,
                sharp,
            } => {
                let pts = points_attr(pts);
                let join = if *sharp { "miter" } else { "round" };
                if *hatch {
                    let _ = writeln!(
                        out,
                        "<g class=\"static\"><polygon points=\"{pts}\"{}/><polygon points=\"{pts}\" \
                         fill=\"url(#hatch)\"{} stroke-width=\"{}\" stroke-linejoin=\"{join}\"/></g>",
                        paint_attr("fill", *fill),
                        paint_attr("stroke", *stroke),
                        num(OUTLINE_WIDTH)
                    );
                } else {
                    let _ = writeln!(
                        out,
                        "<polygon points=\"{pts}\"{}{} stroke-width=\"{}\" stroke-linejoin=\"{join}\"/>",
                        paint_attr("fill", *fill),
                        paint_attr("stroke", *stroke),
                        num(OUTLINE_WIDTH)
                    );
                }
            }
            Prim::Circle {
                c,
                r,
                fill,
                hatch,
                stroke,
            } => {
                let fill_attr = match fill {
                    Some(f) => paint_attr("fill", *f),
                    None => " fill=\"none\"".to_string(),
                };
                let stroke_attr = match stroke {
                    Some((color, width)) => {
                        format!("{} stroke-width=\"{}\"", paint_attr("stroke", *color), num(*width))
                    }
                    None => String::new(),
                };
                let (cx, cy, r) = (num(c[0]), num(c[1]), num(*r));
                if *hatch {
                    let _ = writeln!(
                        out,
                        "<g class=\"static\"><circle cx=\"{cx}\" cy=\"{cy}\" r=\"{r}\"{fill_attr}/><circle cx=\"{cx}\" \
                         cy=\"{cy}\" r=\"{r}\" fill=\"url(#hatch)\"{stroke_attr}/></g>"
                    );
                } else {
                    let _ = writeln!(
                        out,
                        "<circle cx=\"{cx}\" cy=\"{cy}\" r=\"{r}\"{fill_attr}{stroke_attr}/>"
                    );
                }
            }
            Prim::Text {
                x,
                y,
                text,
                color,
                scale,
            } => {
                let s = (*scale).max(1) as f32;
                let _ = writeln!(
                    out,
                    "<text x=\"{}\" y=\"{}\" font-family=\"DejaVu Sans Mono, Menlo, Consolas, monospace\" \
                     font-size=\"{}\" font-weight=\"bold\" textLength=\"{}\" lengthAdjust=\"spacingAndGlyphs\"{}>{}</text>",
                    num(*x),
                    num(*y + 7.0 * s),
                    num(9.5 * s),
                    num(text.chars().count() as f32 * 8.0 * s - s),
                    paint_attr("fill", *color),
                    xml_escape(text)
                );
            }
        }
    }
    if in_grid {
        out.push_str("</g>\n");
    }
    out.push_str("</svg>\n");
    out
}

/// Writes one frame as an SVG file (hand-written SVG, `viewBox` in pixels,
/// same look as the PNG; text uses a bold monospace font instead of the
/// bitmap font).
pub fn write_svg(frame: &Frame, camera: &Camera, path: &FsPath) -> Result<(), RenderError> {
    std::fs::write(path, svg_string(frame, camera)).map_err(io_err(format!("writing {}", path.display())))
}

// ---------------------------------------------------------------------------
// GIF back end
// ---------------------------------------------------------------------------

/// Index of the transparent colour ("unchanged since the previous frame").
const TRANSPARENT: u8 = 255;

/// A 255-colour palette shared by all frames of an animation.
struct Palette {
    colors: Vec<[u8; 3]>,
    cache: HashMap<[u8; 3], u8>,
}

impl Palette {
    /// Chooses the palette: the colours every picture uses, each shape's
    /// fill, then the most frequent colours of a sample of rendered frames.
    fn build(frames: &[Frame], samples: &[Pixmap]) -> Palette {
        let mut colors: Vec<[u8; 3]> = Vec::with_capacity(256);
        let push = |colors: &mut Vec<[u8; 3]>, c: [u8; 3], min_d: i32| {
            if colors.len() < 255 && colors.iter().all(|p| dist2(*p, c) > min_d) {
                colors.push(c);
            }
        };
        let rgb3 = |c: Rgba| [c[0], c[1], c[2]];
        for c in [
            BG,
            OUTLINE,
            TEXT,
            rgb(STICK_COLOR),
            rgb(SLIP_COLOR),
            [255, 255, 255, 255],
            GRID,
            GRID_AXIS,
        ] {
            push(&mut colors, rgb3(c), 0);
        }
        for c in [
            GRID_FINE,
            STATIC_HATCH,
            STATIC_OUTLINE,
            PANEL_STROKE,
            [0x55, 0x52, 0x4d, 255],
        ] {
            push(&mut colors, rgb3(c), 0);
        }
        for frame in frames {
            for s in &frame.shapes {
                let fill = if s.is_static {
                    mix(STATIC_FILL, s.fill, 0.15)
                } else if s.asleep {
                    desaturate(s.fill)
                } else {
                    s.fill
                };
                push(&mut colors, fill, 0);
            }
            if colors.len() >= 128 {
                break;
            }
        }
        // Histogram over 5-bit-per-channel bins, remembering each bin's mean.
        let mut bins: HashMap<u16, (u64, [u64; 3])> = HashMap::new();
        for pm in samples {
            for px in pm.pixels() {
                let c = px.demultiply();
                let key = ((c.red() as u16 >> 3) << 10) | ((c.green() as u16 >> 3) << 5) | (c.blue() as u16 >> 3);
                let e = bins.entry(key).or_insert((0, [0; 3]));
                e.0 += 1;
                e.1[0] += c.red() as u64;
                e.1[1] += c.green() as u64;
                e.1[2] += c.blue() as u64;
            }
        }
        let mut ranked: Vec<(u64, [u8; 3])> = bins
            .values()
            .map(|(n, sum)| {
                let n1 = (*n).max(1);
                (*n, [(sum[0] / n1) as u8, (sum[1] / n1) as u8, (sum[2] / n1) as u8])
            })
            .collect();
        ranked.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
        for min_d in [48, 12, 0] {
            for (_, c) in &ranked {
                push(&mut colors, *c, min_d);
            }
        }
        Palette {
            colors,
            cache: HashMap::new(),
        }
    }

    fn index(&mut self, c: [u8; 3]) -> u8 {
        if let Some(i) = self.cache.get(&c) {
            return *i;
        }
        let mut best = (i32::MAX, 0usize);
        for (i, p) in self.colors.iter().enumerate() {
            let d = dist2(*p, c);
            if d < best.0 {
                best = (d, i);
            }
        }
        let idx = best.1.min(254) as u8;
        self.cache.insert(c, idx);
        idx
    }

    /// 256 × RGB, the last entry being the transparent one.
    fn table(&self) -> Vec<u8> {
        let mut t = Vec::with_capacity(768);
        for i in 0..256 {
            let c = self.colors.get(i).copied().unwrap_or([BG[0], BG[1], BG[2]]);
            t.extend_from_slice(&c);
        }
        t
    }
}

/// Perceptually weighted squared colour distance.
fn dist2(a: [u8; 3], b: [u8; 3]) -> i32 {
    let dr = a[0] as i32 - b[0] as i32;
    let dg = a[1] as i32 - b[1] as i32;
    let db = a[2] as i32 - b[2] as i32;
    2 * dr * dr + 4 * dg * dg + 3 * db * db
}

fn gif_err(e: gif::EncodingError) -> RenderError {
    RenderError::Gif(e.to_string())
}

/// Writes `frames` as an animated GIF that loops forever, `delay_cs`
/// hundredths of a second per frame (browsers treat delays below 2 as 10).
///
/// All frames share one palette chosen from the picture's colours, and each
/// frame after the first only stores the rectangle that changed, with
/// unchanged pixels transparent, which keeps files small. Fails on an
/// empty `frames` slice or a camera larger than 65535 px.
pub fn write_gif(frames: &[Frame], camera: &Camera, delay_cs: u16, path: &FsPath) -> Result<(), RenderError> {
    if frames.is_empty() {
        return Err(RenderError::Invalid("no frames for the GIF".to_string()));
    }
    let (w, h) = (camera.width, camera.height);
    let (w16, h16) = match (u16::try_from(w), u16::try_from(h)) {
        (Ok(a), Ok(b)) => (a, b),
        _ => return Err(RenderError::Invalid(format!("GIF size {w}x{h} exceeds 65535 px"))),
    };
    // Palette from up to 12 frames spread over the animation.
    let n_samples = frames.len().min(12);
    let mut samples = Vec::with_capacity(n_samples);
    for i in 0..n_samples {
        let k = if n_samples > 1 {
            i * (frames.len() - 1) / (n_samples - 1)
        } else {
            0
        };
        if let Some(f) = frames.get(k) {
            samples.push(render_rgba(f, camera)?);
        }
    }
    let mut palette = Palette::build(frames, &samples);
    drop(samples);

    let file = std::fs::File::create(path).map_err(io_err(format!("creating {}", path.display())))?;
    let writer = std::io::BufWriter::new(file);
    let mut encoder = gif::Encoder::new(writer, w16, h16, &palette.table()).map_err(gif_err)?;
    encoder.set_repeat(gif::Repeat::Infinite).map_err(gif_err)?;

    let (wu, hu) = (w as usize, h as usize);
    let mut prev: Option<Vec<u8>> = None;
    for frame in frames {
        let pm = render_rgba(frame, camera)?;
        let idx: Vec<u8> = pm
            .pixels()
            .iter()
            .map(|p| {
                let c = p.demultiply();
                palette.index([c.red(), c.green(), c.blue()])
            })
            .collect();
        let gif_frame = match &prev {
            None => gif::Frame {
                width: w16,
                height: h16,
                delay: delay_cs,
                dispose: gif::DisposalMethod::Keep,
                buffer: Cow::Borrowed(&idx[..]),
                ..gif::Frame::default()
            },
            Some(old) => {
                // Bounding box of changed pixels.
                let (mut x0, mut y0, mut x1, mut y1) = (wu, hu, 0usize, 0usize);
                for y in 0..hu {
                    let row = y * wu;
                    let (a, b) = (&idx[row..row + wu], &old[row..row + wu]);
                    if a == b {
                        continue;
                    }
                    y0 = y0.min(y);
                    y1 = y1.max(y);
                    if let Some(first) = a.iter().zip(b).position(|(p, q)| p != q) {
                        x0 = x0.min(first);
                    }
                    if let Some(last) = a.iter().zip(b).rposition(|(p, q)| p != q) {
                        x1 = x1.max(last);
                    }
                }
                let mut buf = Vec::new();
                let (left, top, fw, fh) = if x0 > x1 || y0 > y1 {
                    buf.push(TRANSPARENT);
                    (0, 0, 1, 1)
                } else {
                    buf.reserve((x1 - x0 + 1) * (y1 - y0 + 1));
                    for y in y0..=y1 {
                        for x in x0..=x1 {
                            let i = y * wu + x;
                            buf.push(if idx[i] == old[i] { TRANSPARENT } else { idx[i] });
                        }
                    }
                    (x0, y0, x1 - x0 + 1, y1 - y0 + 1)
                };
                gif::Frame {
                    left: left as u16,
                    top: top as u16,
                    width: fw as u16,
                    height: fh as u16,
                    delay: delay_cs,
                    dispose: gif::DisposalMethod::Keep,
                    transparent: Some(TRANSPARENT),
                    buffer: Cow::Owned(buf),
                    ..gif::Frame::default()
                }
            }
        };
        encoder.write_frame(&gif_frame).map_err(gif_err)?;
        prev = Some(idx);
    }
    let mut writer = encoder
        .into_inner()
        .map_err(io_err(format!("writing {}", path.display())))?;
    writer.flush().map_err(io_err(format!("writing {}", path.display())))
}

// ---------------------------------------------------------------------------
// Tests
// ---------------------------------------------------------------------------

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{DrawContact, DrawKind, DrawShape, Frame};

    fn shape(kind: DrawKind, fill: [u8; 3], is_static: bool) -> DrawShape {
        DrawShape {
            kind,
            fill,
            is_static,
            asleep: false,
        }
    }

    fn box_points(cx: f32, cy: f32, hw: f32, hh: f32, angle: f32) -> Vec<[f32; 2]> {
        let (s, c) = angle.sin_cos();
        [[-hw, -hh], [hw, -hh], [hw, hh], [-hw, hh]]
            .iter()
            .map(|p| [cx + c * p[0] - s * p[1], cy + s * p[0] + c * p[1]])
            .collect()
    }

    /// Ground box, a box, a circle, a capsule, a segment and two contacts.
    fn scene(time: f32, dx: f32) -> Frame {
        Frame {
            time,
            shapes: vec![
                shape(
                    DrawKind::Polygon {
                        points: box_points(0.0, -0.5, 50.0, 0.5, 0.0),
                        radius: 0.0,
                    },
                    [120, 110, 100],
                    true,
                ),
                shape(
                    DrawKind::Segment {
                        p1: [-3.0, 1.2],
                        p2: [-1.2, 0.0],
                        back: None,
                    },
                    [90, 90, 90],
                    true,
                ),
                shape(
                    DrawKind::Polygon {
                        points: box_points(-0.2 + dx, 0.5, 0.5, 0.5, 0.0),
                        radius: 0.03,
                    },
                    [0x6a, 0xa8, 0xd8],
                    false,
                ),
                shape(
                    DrawKind::Circle {
                        center: [1.3 + dx, 0.4],
                        radius: 0.4,
                        angle: 0.6 + dx,
                    },
                    [0xf2, 0xb1, 0x4c],
                    false,
                ),
                DrawShape {
                    kind: DrawKind::Capsule {
                        p1: [-0.6, 1.25],
                        p2: [0.6, 1.45],
                        radius: 0.25,
                    },
                    fill: [0x8c, 0xc6, 0x7a],
                    is_static: false,
                    asleep: true,
                },
                shape(
                    DrawKind::Polygon {
                        points: box_points(2.4, 0.35, 0.35, 0.35, 0.3),
                        radius: 0.05,
                    },
                    [0xc9, 0x8b, 0xd6],
                    false,
                ),
            ],
            contacts: vec![
                DrawContact {
                    point: [-0.7 + dx, 0.0],
                    normal: [0.0, 1.0],
                    stick: true,
                },
                DrawContact {
                    point: [1.3 + dx, 0.0],
                    normal: [0.0, 1.0],
                    stick: false,
                },
            ],
            joints: vec![[2.0 + dx, 1.5]],
        }
    }

    fn tmpdir(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("tribo_render_{name}_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn near_color(pm: &Pixmap, at: [f32; 2], color: [u8; 3], radius: i32) -> bool {
        for dy in -radius..=radius {
            for dx in -radius..=radius {
                let (x, y) = (at[0] as i32 + dx, at[1] as i32 + dy);
                if x < 0 || y < 0 {
                    continue;
                }
                if let Some(p) = pm.pixel(x as u32, y as u32) {
                    let c = p.demultiply();
                    if dist2([c.red(), c.green(), c.blue()], color) < 200 {
                        return true;
                    }
                }
            }
        }
        false
    }

    #[test]
    fn png_is_valid_and_shows_contacts() {
        let frame = scene(1.25, 0.0);
        let cam = Camera::fit(std::slice::from_ref(&frame), 960, 600);
        let dir = tmpdir("png");
        let path = dir.join("a.png");
        write_png(&frame, &cam, &path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        assert_eq!(&bytes[12..16], b"IHDR");
        assert_eq!(u32::from_be_bytes([bytes[16], bytes[17], bytes[18], bytes[19]]), 960);
        assert_eq!(u32::from_be_bytes([bytes[20], bytes[21], bytes[22], bytes[23]]), 600);
        let pm = Pixmap::decode_png(&bytes).unwrap();
        assert_eq!((pm.width(), pm.height()), (960, 600));
        let mut distinct = std::collections::HashSet::new();
        for p in pm.pixels() {
            distinct.insert((p.red(), p.green(), p.blue()));
        }
        assert!(distinct.len() > 3, "only {} colours", distinct.len());
        assert!(
            near_color(&pm, cam.to_pixel([-0.7, 0.0]), STICK_COLOR, 3),
            "no stick-blue at stick contact"
        );
        assert!(
            near_color(&pm, cam.to_pixel([1.3, 0.0]), SLIP_COLOR, 3),
            "no slip-red at slip contact"
        );
        assert!(!near_color(&pm, cam.to_pixel([-0.7, 0.0]), SLIP_COLOR, 3));
        assert_eq!(png_bytes(&frame, &cam).unwrap(), bytes);
        std::fs::remove_dir_all(&dir).ok();
        // Demo picture for eyeballing.
        write_png(&frame, &cam, &std::env::temp_dir().join("render_demo.png")).unwrap();
    }

    #[test]
    fn svg_is_well_formed() {
        let frame = scene(0.5, 0.0);
        let cam = Camera::fit(std::slice::from_ref(&frame), 960, 600);
        let dir = tmpdir("svg");
        let path = dir.join("a.svg");
        write_svg(&frame, &cam, &path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.starts_with("<svg"));
        assert!(text.trim_end().ends_with("</svg>"));
        assert!(text.contains("viewBox=\"0 0 960 600\""));
        assert!(text.matches("<polygon").count() >= 4, "polygons missing");
        assert!(text.contains("<circle"));
        assert!(text.contains("<line"));
        assert!(text.contains("url(#hatch)"));
        assert!(text.contains("#2f6fdf") && text.contains("#e8512a"));
        assert!(text.contains("t = 0.50 s"));
        assert_eq!(text.matches("<g").count(), text.matches("</g>").count());
        assert!(!text.contains("NaN") && !text.contains("inf"));
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn gif_has_all_frames() {
        let frames: Vec<Frame> = (0..5).map(|i| scene(i as f32 * 0.1, i as f32 * 0.2)).collect();
        let cam = Camera::fit(&frames, 640, 400);
        let dir = tmpdir("gif");
        let path = dir.join("a.gif");
        write_gif(&frames, &cam, 4, &path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(&bytes[..6], b"GIF89a");
        let mut opts = gif::DecodeOptions::new();
        opts.set_color_output(gif::ColorOutput::RGBA);
        let mut dec = opts.read_info(std::fs::File::open(&path).unwrap()).unwrap();
        assert_eq!((dec.width(), dec.height()), (640, 400));
        assert_eq!(dec.repeat(), gif::Repeat::Infinite);
        let mut count = 0;
        while let Some(f) = dec.read_next_frame().unwrap() {
            assert_eq!(f.delay, 4);
            count += 1;
        }
        assert_eq!(count, 5);
        assert!(bytes.len() < 200_000, "GIF too big: {}", bytes.len());
        let empty = write_gif(&[], &cam, 4, &dir.join("b.gif"));
        assert!(matches!(empty, Err(RenderError::Invalid(_))));
        let missing_dir = write_gif(&frames, &cam, 4, &dir.join("no/such/dir/c.gif"));
        assert!(matches!(missing_dir, Err(RenderError::Io { .. })));
        std::fs::remove_dir_all(&dir).ok();
    }

    fn assert_sane(cam: &Camera) {
        assert!(cam.pixels_per_metre().is_finite() && cam.pixels_per_metre() > 0.0);
        assert!(cam.center()[0].is_finite() && cam.center()[1].is_finite());
        let p = cam.to_pixel([0.0, 0.0]);
        assert!(p[0].is_finite() && p[1].is_finite());
    }

    #[test]
    fn camera_fit_degenerate_inputs() {
        let cam = Camera::fit(&[], 960, 600);
        assert_sane(&cam);
        let cam = Camera::fit(&[Frame::default()], 0, 0);
        assert_sane(&cam);
        assert_eq!((cam.width(), cam.height()), (1, 1));
        assert!(render_rgba(&Frame::default(), &cam).is_ok());

        let ground = shape(
            DrawKind::Polygon {
                points: box_points(0.0, -0.5, 50.0, 0.5, 0.0),
                radius: 0.0,
            },
            [1, 2, 3],
            true,
        );
        let only_ground = Frame {
            time: 0.0,
            shapes: vec![ground.clone()],
            contacts: vec![],
            joints: vec![],
        };
        let cam = Camera::fit(std::slice::from_ref(&only_ground), 960, 600);
        assert_sane(&cam);
        assert!(cam.view_width() > 100.0);

        // A huge ground does not shrink a 1 m scene.
        let ball = shape(
            DrawKind::Circle {
                center: [0.0, 0.5],
                radius: 0.5,
                angle: 0.0,
            },
            [200, 100, 50],
            false,
        );
        let small = Frame {
            time: 0.0,
            shapes: vec![ground, ball],
            contacts: vec![],
            joints: vec![],
        };
        let cam = Camera::fit(std::slice::from_ref(&small), 960, 600);
        assert_sane(&cam);
        assert!(cam.view_width() < 6.0, "view {} m", cam.view_width());
        let c = cam.to_pixel([0.0, 0.5]);
        assert!(c[0] > 0.0 && c[0] < 960.0 && c[1] > 40.0 && c[1] < 600.0);

        // A point-like dynamic shape still gives a 2 m view.
        let dot = shape(
            DrawKind::Segment {
                p1: [3.0, 3.0],
                p2: [3.0, 3.0],
                back: None,
            },
            [0, 0, 0],
            false,
        );
        let cam = Camera::fit(
            &[Frame {
                time: 0.0,
                shapes: vec![dot],
                contacts: vec![],
                joints: vec![],
            }],
            640,
            400,
        );
        assert_sane(&cam);
        assert!(cam.view_width() >= 2.0);

        // NaN geometry is ignored.
        let bad = shape(
            DrawKind::Circle {
                center: [f32::NAN, 0.0],
                radius: f32::INFINITY,
                angle: 0.0,
            },
            [0, 0, 0],
            false,
        );
        let frame = Frame {
            time: f32::NAN,
            shapes: vec![bad],
            contacts: vec![],
            joints: vec![],
        };
        let cam = Camera::fit(std::slice::from_ref(&frame), 640, 400);
        assert_sane(&cam);
        assert!(render_rgba(&frame, &cam).is_ok());
        assert!(!svg_string(&frame, &cam).contains("NaN"));
    }

    #[test]
    fn scale_labels() {
        assert_eq!(scale_label(1.0), "1 m");
        assert_eq!(scale_label(10.0), "10 m");
        assert_eq!(scale_label(0.2), "20 cm");
        assert_eq!(scale_label(0.005), "5 mm");
        assert_eq!(scale_label(2000.0), "2 km");
    }

    #[test]
    fn rounded_outlines_are_bounded() {
        let sq = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]];
        let pts = rounded_polygon_points(&sq, 2.0);
        for p in &pts {
            assert!(p[0] >= -2.01 && p[0] <= 12.01 && p[1] >= -2.01 && p[1] <= 12.01);
        }
        assert!(pts.iter().any(|p| p[0] < -1.99) && pts.iter().any(|p| p[1] > 11.99));
        let clipped = clip_polygon(pts, [0.0, 0.0], [5.0, 5.0]);
        assert!(clipped
            .iter()
            .all(|p| p[0] >= -1e-3 && p[0] <= 5.001 && p[1] >= -1e-3 && p[1] <= 5.001));
    }
}
