//! The validation report of `tribo validate`: a plain-text table for the terminal and a
//! self-contained HTML page (inline CSS, hand-written SVG plots, PNG pictures as data URIs;
//! nothing is fetched from the network).

use std::fmt::{self, Write as _};
use std::path::{Path, PathBuf};

use base64::Engine as _;
use tribo_scenes::validation::{Check, Tolerance};

/// A picture to embed: a caption and PNG bytes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Picture {
    /// Text shown under the picture (plain text; escaped when written).
    pub caption: String,
    /// The encoded PNG file.
    pub png: Vec<u8>,
}

// ---------------------------------------------------------------------------------------
// Numbers, units, tolerances
// ---------------------------------------------------------------------------------------

/// Removes trailing zeros of a decimal mantissa: "1.2500" → "1.25", "2.000" → "2".
fn trim_zeros(s: &str) -> String {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s.to_string()
    }
}

/// A number in 4 significant digits; scientific below 1e-3 and from 1e6 on; integers
/// printed as integers; trailing zeros dropped.
fn fmt_num(x: f64) -> String {
    if x.is_nan() {
        return "NaN".into();
    }
    if x.is_infinite() {
        return if x > 0.0 { "∞".into() } else { "−∞".into() };
    }
    if x == 0.0 {
        return "0".into();
    }
    let a = x.abs();
    if !(1e-3..1e6).contains(&a) {
        let s = format!("{x:.3e}");
        return match s.split_once('e') {
            Some((mantissa, exp)) => format!("{}e{exp}", trim_zeros(mantissa)),
            None => s,
        };
    }
    if x.fract() == 0.0 {
        return format!("{x:.0}");
    }
    let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
    trim_zeros(&format!("{x:.decimals$}"))
}

/// A value followed by its unit (no unit: the bare number).
fn with_unit(x: f64, unit: &str) -> String {
    if unit.is_empty() {
        fmt_num(x)
    } else {
        format!("{} {unit}", fmt_num(x))
    }
}

/// The deviation in the tolerance's terms: a percentage for relative tolerances.
fn fmt_error(c: &Check) -> String {
    let e = c.error();
    match c.tolerance {
        Tolerance::Relative(_) if c.expected != 0.0 => format!("{} %", fmt_num(e * 100.0)),
        _ => with_unit(e, c.unit),
    }
}

/// The tolerance as a condition: "±1 %", "± 0.2 m", "≤ 0.05 mm", "≥ 20 bounces".
fn fmt_tolerance(c: &Check) -> String {
    match c.tolerance {
        Tolerance::Relative(r) => format!("±{} %", fmt_num(r * 100.0)),
        Tolerance::Absolute(a) => format!("± {}", with_unit(a, c.unit)),
        Tolerance::AtMost(m) => format!("≤ {}", with_unit(m, c.unit)),
        Tolerance::AtLeast(m) => format!("≥ {}", with_unit(m, c.unit)),
    }
}

/// Label of the PASS/FAIL column.
fn verdict(c: &Check) -> &'static str {
    if c.passed() {
        "PASS"
    } else {
        "FAIL"
    }
}

/// (passed, failed).
fn counts(checks: &[Check]) -> (usize, usize) {
    let passed = checks.iter().filter(|c| c.passed()).count();
    (passed, checks.len() - passed)
}

/// The y-axis title of a check's series.
///
/// `Check` does not say what its series samples, so this follows the convention of the
/// experiments: accelerations are fitted from velocity curves, and times (time to roll,
/// time to reach a belt speed) are read off velocity curves too; lengths are positions.
fn series_quantity(c: &Check) -> String {
    match c.unit {
        "m/s" | "m/s²" | "s" => "v [m/s]".into(),
        "m" | "cm" | "mm" => format!("x [{}]", c.unit),
        "" => "value".into(),
        u => format!("value [{u}]"),
    }
}

// ---------------------------------------------------------------------------------------
// Plain-text table
// ---------------------------------------------------------------------------------------

/// The plain-text table the CLI prints: one row per check with the columns
/// experiment | formula | expected | measured | error | tolerance | pass (numbers in 4
/// significant digits with their units, relative errors in %), then a final line
/// "N passed, M failed".
pub fn format_table(checks: &[Check]) -> String {
    const HEADER: [&str; 7] = [
        "experiment",
        "formula",
        "expected",
        "measured",
        "error",
        "tolerance",
        "pass",
    ];
    // Right-aligned columns: the numbers.
    const RIGHT: [bool; 7] = [false, false, true, true, true, false, false];
    let rows: Vec<[String; 7]> = checks
        .iter()
        .map(|c| {
            [
                c.experiment.clone(),
                c.formula.clone(),
                with_unit(c.expected, c.unit),
                with_unit(c.measured, c.unit),
                fmt_error(c),
                fmt_tolerance(c),
                verdict(c).to_string(),
            ]
        })
        .collect();
    let mut widths = HEADER.map(|h| h.chars().count());
    for row in &rows {
        for (w, cell) in widths.iter_mut().zip(row) {
            *w = (*w).max(cell.chars().count());
        }
    }
    let line = |cells: &[String; 7]| -> String {
        let mut s = String::new();
        for (i, cell) in cells.iter().enumerate() {
            if i > 0 {
                s.push_str("  ");
            }
            let pad = " ".repeat(widths[i].saturating_sub(cell.chars().count()));
            if RIGHT[i] {
                s.push_str(&pad);
                s.push_str(cell);
            } else {
                s.push_str(cell);
                if i + 1 < cells.len() {
                    s.push_str(&pad);
                }
            }
        }
        s.push('\n');
        s
    };
    let mut out = line(&HEADER.map(String::from));
    let total: usize = widths.iter().sum::<usize>() + 2 * (widths.len() - 1);
    out.push_str(&"-".repeat(total));
    out.push('\n');
    for row in &rows {
        out.push_str(&line(row));
    }
    let (passed, failed) = counts(checks);
    out.push_str(&format!("{passed} passed, {failed} failed\n"));
    out
}

// ---------------------------------------------------------------------------------------
// HTML
// ---------------------------------------------------------------------------------------

/// Escapes text for HTML element content and quoted attribute values.
fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// Escapes a formatted value for HTML and typesets its numbers: true minus signs and
/// scientific notation as "3.49 × 10<sup>−8</sup>".
fn html_value(s: &str) -> String {
    s.split(' ')
        .map(|token| {
            let is_number = token.parse::<f64>().is_ok_and(f64::is_finite);
            if !is_number {
                return escape(token);
            }
            let token = token.replace('-', "−");
            match token.split_once('e') {
                Some(("1", exp)) => format!("10<sup>{exp}</sup>"),
                Some((mantissa, exp)) => format!("{mantissa}&#8239;×&#8239;10<sup>{exp}</sup>"),
                None => token,
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

const STYLE: &str = r#"
:root { --pass: #15803d; --pass-bg: #dcfce7; --fail: #b91c1c; --fail-bg: #fee2e2;
        --ink: #1f2937; --muted: #6b7280; --line: #e5e7eb; --card: #ffffff; --page: #f6f7f9; }
* { box-sizing: border-box; }
body { margin: 0; background: var(--page); color: var(--ink);
       font: 15px/1.5 -apple-system, BlinkMacSystemFont, "Segoe UI", Roboto, "Helvetica Neue",
             Arial, "Noto Sans", sans-serif; }
main { max-width: 1100px; margin: 0 auto; padding: 32px 24px 64px; }
h1 { font-size: 28px; margin: 0 0 4px; letter-spacing: -0.01em; }
h2 { font-size: 20px; margin: 40px 0 12px; }
.info { color: var(--muted); margin: 0 0 24px; white-space: pre-wrap; }
.summary { display: flex; align-items: center; gap: 32px; flex-wrap: wrap; padding: 20px 28px;
           border-radius: 12px; background: var(--card); border: 1px solid var(--line);
           border-left: 10px solid var(--pass); }
.summary.bad { border-left-color: var(--fail); }
.summary .count { display: flex; align-items: baseline; gap: 10px; }
.summary .n { font-size: 52px; font-weight: 700; line-height: 1; font-variant-numeric: tabular-nums; }
.summary .label { font-size: 20px; color: var(--muted); }
.summary .passed .n { color: var(--pass); }
.summary .failed .n { color: var(--fail); }
.summary .failed.zero .n { color: #9ca3af; }
.summary .verdict { margin-left: auto; font-size: 18px; font-weight: 700; padding: 8px 16px;
                    border-radius: 999px; background: var(--pass-bg); color: var(--pass); }
.summary.bad .verdict { background: var(--fail-bg); color: var(--fail); }
table { width: 100%; border-collapse: collapse; background: var(--card); font-size: 13.5px;
        border: 1px solid var(--line); border-radius: 8px; overflow: hidden; }
th, td { padding: 7px 10px; text-align: left; vertical-align: top; border-bottom: 1px solid var(--line); }
th { background: #f3f4f6; font-weight: 600; color: #374151; white-space: nowrap; }
td.num { text-align: right; white-space: nowrap; font-variant-numeric: tabular-nums; }
td.tol, td.exp { white-space: nowrap; }
td.exp { font-weight: 600; }
td.exp.cont { color: transparent; }
tr.fail td { background: var(--fail-bg); }
tr.fail td.exp.cont { color: transparent; }
.badge { display: inline-block; min-width: 44px; text-align: center; padding: 1px 8px;
         border-radius: 999px; font-size: 12px; font-weight: 700; }
.badge.pass { background: var(--pass-bg); color: var(--pass); }
.badge.fail { background: var(--fail); color: #fff; }
sup { font-size: 0.72em; line-height: 0; vertical-align: 0.45em; }
a { color: #2563eb; text-decoration: none; }
a:hover { text-decoration: underline; }
.plots { display: grid; grid-template-columns: repeat(auto-fill, minmax(480px, 1fr)); gap: 16px; }
figure { margin: 0; background: var(--card); border: 1px solid var(--line); border-radius: 10px;
         padding: 14px 16px 10px; }
figure.fail { border-color: #fca5a5; }
figure .head { display: flex; gap: 8px; align-items: baseline; justify-content: space-between; }
figure .title { font-weight: 600; }
figure .formula { color: #374151; font-size: 13.5px; margin: 2px 0 4px; }
figure .values { color: var(--muted); font-size: 12.5px; font-variant-numeric: tabular-nums; }
figure svg { display: block; width: 100%; height: auto; margin-top: 6px; }
.pictures figure { margin-bottom: 16px; }
.pictures img { display: block; max-width: 100%; height: auto; margin: 0 auto;
                border: 1px solid var(--line); border-radius: 6px; }
.pictures figcaption { color: #374151; font-size: 14px; margin-top: 8px; text-align: center; }
footer { margin-top: 48px; color: var(--muted); font-size: 12.5px; }
"#;

/// The whole report page: a summary (N passed / M failed), the table of checks (failed
/// rows highlighted), an SVG plot of measured (solid) against analytic (dashed) for every
/// check with a non-empty series, then the pictures with their captions. `title_info` is
/// shown under the title (e.g. version, date, settings). The page is self-contained.
pub fn render_html(checks: &[Check], pictures: &[Picture], title_info: &str) -> String {
    let mut out = String::new();
    // Writing into a String cannot fail; an error here would only mean a formatting bug.
    if write_page(&mut out, checks, pictures, title_info).is_err() {
        out.push_str("<!-- report formatting failed -->");
    }
    out
}

/// Creates `dir` (and its parents), writes the report of [`render_html`] to
/// `dir/index.html` and returns that path.
pub fn write_report(dir: &Path, checks: &[Check], pictures: &[Picture], title_info: &str) -> std::io::Result<PathBuf> {
    std::fs::create_dir_all(dir)?;
    let path = dir.join("index.html");
    std::fs::write(&path, render_html(checks, pictures, title_info))?;
    Ok(path)
}

fn write_page(out: &mut String, checks: &[Check], pictures: &[Picture], title_info: &str) -> fmt::Result {
    let (passed, failed) = counts(checks);
    writeln!(out, "<!DOCTYPE html>")?;
    writeln!(out, "<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">")?;
    writeln!(
        out,
        "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
    )?;
    writeln!(
        out,
        "<title>Tribo validation — {passed} passed, {failed} failed</title>"
    )?;
    writeln!(out, "<style>{STYLE}</style>\n</head>\n<body>\n<main>")?;
    writeln!(out, "<h1>Tribo validation report</h1>")?;
    if !title_info.is_empty() {
        writeln!(out, "<p class=\"info\">{}</p>", escape(title_info))?;
    }

    // Summary.
    let bad = if failed > 0 { " bad" } else { "" };
    let zero = if failed == 0 { " zero" } else { "" };
    let verdict = if checks.is_empty() {
        "no checks".to_string()
    } else if failed == 0 {
        "all checks pass".to_string()
    } else {
        format!("{failed} of {} checks fail", checks.len())
    };
    writeln!(out, "<section class=\"summary{bad}\">")?;
    writeln!(
        out,
        "<div class=\"count passed\"><span class=\"n\">{passed}</span><span class=\"label\">passed</span></div>"
    )?;
    writeln!(
        out,
        "<div class=\"count failed{zero}\"><span class=\"n\">{failed}</span><span class=\"label\">failed</span></div>"
    )?;
    writeln!(out, "<div class=\"verdict\">{verdict}</div>\n</section>")?;

    write_table(out, checks)?;

    let plotted: Vec<(usize, &Check)> = checks
        .iter()
        .enumerate()
        .filter(|(_, c)| !c.series.is_empty())
        .collect();
    if !plotted.is_empty() {
        writeln!(out, "<h2>Measured against analytic</h2>\n<section class=\"plots\">")?;
        for (i, c) in plotted {
            write_plot_figure(out, i, c)?;
        }
        writeln!(out, "</section>")?;
    }

    if !pictures.is_empty() {
        writeln!(out, "<h2>Pictures</h2>\n<section class=\"pictures\">")?;
        for p in pictures {
            let caption = escape(&p.caption);
            let data = base64::engine::general_purpose::STANDARD.encode(&p.png);
            writeln!(
                out,
                "<figure><img src=\"data:image/png;base64,{data}\" alt=\"{caption}\"><figcaption>{caption}</figcaption></figure>"
            )?;
        }
        writeln!(out, "</section>")?;
    }
    writeln!(
        out,
        "<footer>Errors are relative (in %) for relative tolerances, absolute otherwise. \
         Generated by <code>tribo validate --report</code>.</footer>"
    )?;
    writeln!(out, "</main>\n</body>\n</html>")
}

fn write_table(out: &mut String, checks: &[Check]) -> fmt::Result {
    writeln!(out, "<h2>Checks</h2>\n<table>")?;
    writeln!(
        out,
        "<thead><tr><th>experiment</th><th>formula</th><th>expected</th><th>measured</th>\
         <th>error</th><th>tolerance</th><th>result</th></tr></thead>\n<tbody>"
    )?;
    let mut previous: Option<&str> = None;
    for (i, c) in checks.iter().enumerate() {
        let row_class = if c.passed() { "pass" } else { "fail" };
        // The experiment name only on the first row of a group (kept for copy-paste).
        let cont = if previous == Some(c.experiment.as_str()) {
            " cont"
        } else {
            ""
        };
        previous = Some(c.experiment.as_str());
        let formula = if c.series.is_empty() {
            escape(&c.formula)
        } else {
            format!("<a href=\"#check-{i}\">{}</a>", escape(&c.formula))
        };
        writeln!(
            out,
            "<tr class=\"{row_class}\"><td class=\"exp{cont}\">{}</td><td>{formula}</td>\
             <td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>\
             <td class=\"tol\">{}</td><td><span class=\"badge {row_class}\">{}</span></td></tr>",
            escape(&c.experiment),
            html_value(&with_unit(c.expected, c.unit)),
            html_value(&with_unit(c.measured, c.unit)),
            html_value(&fmt_error(c)),
            html_value(&fmt_tolerance(c)),
            verdict(c),
        )?;
    }
    writeln!(out, "</tbody>\n</table>")
}

fn write_plot_figure(out: &mut String, index: usize, c: &Check) -> fmt::Result {
    let class = if c.passed() { "pass" } else { "fail" };
    writeln!(out, "<figure class=\"{class}\" id=\"check-{index}\">")?;
    writeln!(
        out,
        "<div class=\"head\"><span class=\"title\">{}</span><span class=\"badge {class}\">{}</span></div>",
        escape(&c.experiment),
        verdict(c)
    )?;
    writeln!(out, "<div class=\"formula\">{}</div>", escape(&c.formula))?;
    writeln!(
        out,
        "<div class=\"values\">expected {} · measured {} · error {} (tolerance {})</div>",
        html_value(&with_unit(c.expected, c.unit)),
        html_value(&with_unit(c.measured, c.unit)),
        html_value(&fmt_error(c)),
        html_value(&fmt_tolerance(c)),
    )?;
    write_svg(out, &c.series, &series_quantity(c))?;
    writeln!(out, "</figure>")
}

// ---------------------------------------------------------------------------------------
// SVG plots
// ---------------------------------------------------------------------------------------

/// Tick positions for [lo, hi]: a 1-2-5 step giving about `target` intervals, and the
/// range widened to whole steps. Returns (start, end, step).
fn nice_ticks(lo: f64, hi: f64, target: f64) -> (f64, f64, f64) {
    let span = hi - lo;
    let raw = span / target;
    let mag = 10f64.powf(raw.log10().floor());
    let norm = raw / mag;
    let step = if norm <= 1.0 {
        1.0
    } else if norm <= 2.0 {
        2.0
    } else if norm <= 2.5 {
        2.5
    } else if norm <= 5.0 {
        5.0
    } else {
        10.0
    } * mag;
    // The small slack keeps a bound that sits on a step (up to float noise) from gaining
    // a whole empty interval.
    let start = (lo / step + 1e-9).floor() * step;
    let end = (hi / step - 1e-9).ceil() * step;
    (start, end, step)
}

/// A tick label: as many decimals as the step needs; scientific for extreme magnitudes.
fn tick_label(v: f64, step: f64) -> String {
    let v = if (v / step).abs() < 1e-9 { 0.0 } else { v };
    let a = step.abs();
    if !(1e-3..1e6).contains(&a) {
        return fmt_num(v);
    }
    // The fewest decimals that write the step exactly (0.25 needs 2, 0.5 needs 1).
    let decimals = (0..=9usize)
        .find(|&d| {
            let scaled = a * 10f64.powi(d as i32);
            (scaled - scaled.round()).abs() < 1e-6 * scaled
        })
        .unwrap_or(9);
    let s = format!("{v:.decimals$}");
    s.replace('-', "−")
}

/// Finite range of values, widened when degenerate; None when nothing is finite.
fn range(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return None;
    }
    if hi - lo <= 1e-12 * lo.abs().max(hi.abs()).max(1e-300) {
        let pad = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
        return Some((lo - pad, hi + pad));
    }
    Some((lo, hi))
}

/// An SVG path through the points, broken wherever a value is not finite.
fn polyline_path(points: impl Iterator<Item = (f64, f64)>, sx: impl Fn(f64) -> f64, sy: impl Fn(f64) -> f64) -> String {
    let mut d = String::new();
    let mut pen_down = false;
    for (x, y) in points {
        if !(x.is_finite() && y.is_finite()) {
            pen_down = false;
            continue;
        }
        let cmd = if pen_down { 'L' } else { 'M' };
        // Writing into a String cannot fail.
        let _ = write!(d, "{cmd}{:.1},{:.1}", sx(x), sy(y));
        pen_down = true;
    }
    d
}

/// A line chart of measured (solid) and analytic (dashed) against time, with ticks,
/// grid, legend and axis titles "t [s]" and `y_title`.
fn write_svg(out: &mut String, series: &[(f64, f64, f64)], y_title: &str) -> fmt::Result {
    const W: f64 = 560.0;
    const H: f64 = 330.0;
    const LEFT: f64 = 66.0;
    const RIGHT: f64 = 18.0;
    const TOP: f64 = 34.0;
    const BOTTOM: f64 = 50.0;
    const MEASURED: &str = "#2563eb";
    const ANALYTIC: &str = "#ea580c";

    let Some((x0, x1)) = range(series.iter().map(|s| s.0)) else {
        return writeln!(out, "<p class=\"values\">(no finite samples to plot)</p>");
    };
    let Some((y0, y1)) = range(series.iter().flat_map(|s| [s.1, s.2])) else {
        return writeln!(out, "<p class=\"values\">(no finite samples to plot)</p>");
    };
    // Time axis from 0 when the samples start near it.
    let x0 = if x0 > 0.0 && x0 < 0.1 * (x1 - x0) { 0.0 } else { x0 };
    // The time axis spans the samples exactly; ticks fall on round values inside it.
    let (xa, xb) = (x0, x1);
    let (_, _, xs) = nice_ticks(x0, x1, 6.0);
    let (ya, yb, ys) = nice_ticks(y0, y1, 5.0);
    let (pw, ph) = (W - LEFT - RIGHT, H - TOP - BOTTOM);
    let sx = |x: f64| LEFT + (x - xa) / (xb - xa) * pw;
    let sy = |y: f64| TOP + ph - (y - ya) / (yb - ya) * ph;

    writeln!(
        out,
        "<svg viewBox=\"0 0 {W} {H}\" role=\"img\" aria-label=\"measured and analytic {} against time\" \
         font-family=\"-apple-system, BlinkMacSystemFont, Segoe UI, Roboto, Helvetica, Arial, sans-serif\" font-size=\"12\">",
        escape(y_title)
    )?;
    writeln!(
        out,
        "<rect x=\"{LEFT}\" y=\"{TOP}\" width=\"{pw}\" height=\"{ph}\" fill=\"#fbfbfc\"/>"
    )?;

    // Grid, ticks and tick labels.
    let first_x = (xa / xs - 1e-9).ceil() as i64;
    let last_x = (xb / xs + 1e-9).floor() as i64;
    for k in first_x..=last_x {
        let v = k as f64 * xs;
        let x = sx(v);
        writeln!(
            out,
            "<line x1=\"{x:.1}\" y1=\"{TOP}\" x2=\"{x:.1}\" y2=\"{:.1}\" stroke=\"#e5e7eb\"/>\
             <line x1=\"{x:.1}\" y1=\"{:.1}\" x2=\"{x:.1}\" y2=\"{:.1}\" stroke=\"#374151\"/>\
             <text x=\"{x:.1}\" y=\"{:.1}\" text-anchor=\"middle\" fill=\"#374151\">{}</text>",
            TOP + ph,
            TOP + ph,
            TOP + ph + 5.0,
            TOP + ph + 19.0,
            tick_label(v, xs)
        )?;
    }
    let n_y = ((yb - ya) / ys).round() as i64;
    for k in 0..=n_y {
        let v = ya + k as f64 * ys;
        let y = sy(v);
        writeln!(
            out,
            "<line x1=\"{LEFT}\" y1=\"{y:.1}\" x2=\"{:.1}\" y2=\"{y:.1}\" stroke=\"#e5e7eb\"/>\
             <line x1=\"{:.1}\" y1=\"{y:.1}\" x2=\"{LEFT}\" y2=\"{y:.1}\" stroke=\"#374151\"/>\
             <text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\" fill=\"#374151\">{}</text>",
            LEFT + pw,
            LEFT - 5.0,
            LEFT - 8.0,
            y + 4.0,
            tick_label(v, ys)
        )?;
    }
    // Axes.
    writeln!(
        out,
        "<path d=\"M{LEFT},{TOP}V{:.1}H{:.1}\" fill=\"none\" stroke=\"#374151\" stroke-width=\"1.2\"/>",
        TOP + ph,
        LEFT + pw
    )?;

    // Curves: measured under, analytic dashed on top, so both show where they coincide.
    writeln!(
        out,
        "<path d=\"{}\" fill=\"none\" stroke=\"{MEASURED}\" stroke-width=\"3.5\" stroke-linejoin=\"round\" opacity=\"0.8\"/>",
        polyline_path(series.iter().map(|s| (s.0, s.1)), sx, sy)
    )?;
    writeln!(
        out,
        "<path d=\"{}\" fill=\"none\" stroke=\"{ANALYTIC}\" stroke-width=\"2\" stroke-dasharray=\"7 5\"/>",
        polyline_path(series.iter().map(|s| (s.0, s.2)), sx, sy)
    )?;

    // Legend above the plot area, right-aligned.
    let lx = LEFT + pw - 190.0;
    let ly = TOP - 14.0;
    writeln!(
        out,
        "<line x1=\"{lx}\" y1=\"{ly}\" x2=\"{:.1}\" y2=\"{ly}\" stroke=\"{MEASURED}\" stroke-width=\"3.5\" opacity=\"0.8\"/>\
         <text x=\"{:.1}\" y=\"{:.1}\" fill=\"#1f2937\">measured</text>\
         <line x1=\"{:.1}\" y1=\"{ly}\" x2=\"{:.1}\" y2=\"{ly}\" stroke=\"{ANALYTIC}\" stroke-width=\"2\" stroke-dasharray=\"7 5\"/>\
         <text x=\"{:.1}\" y=\"{:.1}\" fill=\"#1f2937\">analytic</text>",
        lx + 24.0,
        lx + 30.0,
        ly + 4.0,
        lx + 100.0,
        lx + 124.0,
        lx + 130.0,
        ly + 4.0,
    )?;

    // Axis titles.
    writeln!(
        out,
        "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\" font-size=\"13\" fill=\"#111827\">t [s]</text>",
        LEFT + pw / 2.0,
        H - 10.0
    )?;
    writeln!(
        out,
        "<text transform=\"translate(16 {:.1}) rotate(-90)\" text-anchor=\"middle\" font-size=\"13\" fill=\"#111827\">{}</text>",
        TOP + ph / 2.0,
        escape(y_title)
    )?;
    writeln!(out, "</svg>")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(experiment: &str, formula: &str, expected: f64, measured: f64, tol: Tolerance, series: bool) -> Check {
        Check {
            experiment: experiment.into(),
            formula: formula.into(),
            expected,
            measured,
            tolerance: tol,
            unit: "m/s²",
            series: if series {
                (1..=60)
                    .map(|k| (k as f64 / 60.0, 0.1 * k as f64, 0.1 * k as f64 + 0.01))
                    .collect()
            } else {
                Vec::new()
            },
        }
    }

    fn sample() -> Vec<Check> {
        vec![
            check(
                "slide",
                "a = g (sin θ − μd cos θ) & x < y",
                2.0,
                2.01,
                Tolerance::Relative(0.01),
                true,
            ),
            check("slide", "creep", 0.0, 0.2, Tolerance::AtMost(0.05), false),
            check("roll", "v = 2/3 v0", 1.0, 1.0, Tolerance::Absolute(0.1), true),
            check("bounce", "count ≥ 20", 20.0, f64::NAN, Tolerance::AtLeast(20.0), false),
        ]
    }

    #[test]
    fn html_has_summary_plots_and_escapes() {
        let checks = sample();
        let pics = [Picture {
            caption: "scene <1>".into(),
            png: vec![0x89, b'P', b'N', b'G'],
        }];
        let html = render_html(&checks, &pics, "version 0.1 <dev>");
        assert!(html.contains("<span class=\"n\">2</span><span class=\"label\">passed</span>"));
        assert!(html.contains("<span class=\"n\">2</span><span class=\"label\">failed</span>"));
        assert_eq!(html.matches("<svg").count(), 2);
        assert!(html.contains("x &lt; y"));
        assert!(html.contains("&amp;"));
        assert!(!html.contains("x < y"));
        assert!(html.contains("version 0.1 &lt;dev&gt;"));
        assert!(html.contains("scene &lt;1&gt;"));
        assert!(html.contains("data:image/png;base64,iVBORw=="));
        assert!(!html.contains("http://") && !html.contains("https://"));
        assert_eq!(html.matches("<tr class=\"fail\">").count(), 2);
    }

    #[test]
    fn table_has_one_row_per_check_and_summary() {
        let checks = sample();
        let table = format_table(&checks);
        let lines: Vec<&str> = table.lines().collect();
        // header, rule, rows, summary
        assert_eq!(lines.len(), checks.len() + 3);
        assert_eq!(lines.last().copied(), Some("2 passed, 2 failed"));
        let rows = &lines[2..2 + checks.len()];
        assert_eq!(rows.iter().filter(|l| l.ends_with("PASS")).count(), 2);
        assert_eq!(rows.iter().filter(|l| l.ends_with("FAIL")).count(), 2);
        // Aligned: every row as wide as the header (in characters).
        let width = lines[0].chars().count();
        assert!(rows.iter().all(|l| l.chars().count() == width));
        assert!(rows[0].contains("2.01 m/s²") && rows[0].contains("0.5 %") && rows[0].contains("±1 %"));
    }

    #[test]
    fn numbers() {
        assert_eq!(fmt_num(0.0), "0");
        assert_eq!(fmt_num(20.0), "20");
        assert_eq!(fmt_num(2.0 / 3.0), "0.6667");
        assert_eq!(fmt_num(1234.5678), "1235");
        assert_eq!(fmt_num(12.5), "12.5");
        assert_eq!(fmt_num(3.2e-7), "3.2e-7");
        assert_eq!(fmt_num(-1.23456e-5), "-1.235e-5");
        assert_eq!(fmt_num(f64::NAN), "NaN");
        assert_eq!(nice_ticks(0.0, 1.93, 6.0), (0.0, 2.0, 0.5));
        assert_eq!(tick_label(0.25, 0.25), "0.25");
        assert_eq!(tick_label(-1.0, 0.5), "−1.0");
        assert_eq!(html_value("3.49e-8 m"), "3.49&#8239;×&#8239;10<sup>−8</sup> m");
        assert_eq!(html_value("≤ 1e-6"), "≤ 10<sup>−6</sup>");
        assert_eq!(html_value("a<b -x"), "a&lt;b -x");
        assert_eq!(html_value("-6.748 mm"), "−6.748 mm");
    }

    #[test]
    fn degenerate_series_still_plots() {
        let mut c = check("flat", "constant", 1.0, 1.0, Tolerance::Relative(0.01), false);
        c.series = vec![(0.0, 1.0, 1.0), (1.0, 1.0, 1.0), (2.0, f64::NAN, 1.0)];
        let html = render_html(&[c], &[], "");
        assert_eq!(html.matches("<svg").count(), 1);
        assert!(!html.contains("NaN,"));
    }
}
