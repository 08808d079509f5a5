//! The shared look: the bundled font, sizes, colours, number formats and a symmetric-log axis.

use plotters::chart::{ChartContext, MeshStyle, SeriesLabelPosition};
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint};
use plotters::coord::CoordTranslate;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{FontStyle, RGBColor};
use std::cell::Cell;
use std::ops::Range;
use std::sync::Once;

/// DejaVu Sans, bundled: plots look the same on every machine.
pub(crate) static DEJAVU_SANS: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

/// The font family every plot uses (registered to the bundled font).
pub const FAMILY: &str = "sans-serif";

/// Registers the bundled font as `sans-serif` (once per process).
pub fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The font is a fixed, valid TrueType file; if plotters ever rejected it the text would
        // be missing from the PNG, never a crash.
        let _ = plotters::style::register_font(FAMILY, FontStyle::Normal, DEJAVU_SANS);
        let _ = plotters::style::register_font(FAMILY, FontStyle::Bold, DEJAVU_SANS);
    });
}

thread_local! {
    /// Drawn pixels per pixel of the finished figure: > 1 while a supersampled PNG is drawn.
    static SCALE: Cell<u32> = const { Cell::new(1) };
}

/// `n` pixels of the finished figure, in the pixels being drawn. A figure drawn supersampled
/// ([`super::Figure::SUPERSAMPLE`]) gives every size, margin and offset through this, so that it
/// looks the same at any scale.
pub fn px(n: u32) -> u32 {
    n * SCALE.with(Cell::get)
}

/// [`px`] for signed offsets.
pub fn pxi(n: i32) -> i32 {
    n * SCALE.with(Cell::get) as i32
}

/// Runs `draw` with [`px`] scaling by `scale`, restoring the previous scale afterwards.
pub(super) fn scaled<R>(scale: u32, draw: impl FnOnce() -> R) -> R {
    let old = SCALE.with(|s| s.replace(scale.max(1)));
    let out = draw();
    SCALE.with(|s| s.set(old));
    out
}

/// Figure title size (px).
pub const TITLE: u32 = 24;
/// Panel caption size (px).
pub const CAPTION: u32 = 19;
/// Axis title size (px).
pub const AXIS: u32 = 18;
/// Tick label size (px).
pub const TICK: u32 = 15;
/// Legend and annotation size (px).
pub const LEGEND: u32 = 15;

/// The font at `size` px.
pub fn font(size: u32) -> FontDesc<'static> {
    (FAMILY, px(size)).into_font()
}

/// The font at `size` px in `colour`.
pub fn text(size: u32, colour: RGBColor) -> TextStyle<'static> {
    font(size).color(&colour)
}

/// Near-black for text and axes.
pub const INK: RGBColor = RGBColor(30, 30, 30);
/// Mid grey for guides.
pub const GUIDE: RGBColor = RGBColor(120, 120, 120);
/// Light grey for grids and failed cells.
pub const LIGHT: RGBColor = RGBColor(225, 225, 225);

/// Colours of the modes (1, 2, 3, …), colour-blind-safe (Okabe–Ito).
pub const MODES: [RGBColor; 6] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
];

/// Colour of mode `k` (0-based).
pub fn mode_colour(k: usize) -> RGBColor {
    MODES[k % MODES.len()]
}

/// Colours of the parameters of one run, in order (Okabe–Ito without the yellow, which is too
/// pale on white): seven colours that colour-blind readers tell apart.
pub const SERIES: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(30, 30, 30),
];

/// How a line is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Dash {
    /// Unbroken.
    Solid,
    /// 8 px dashes.
    Dashed,
    /// 2 px dots.
    Dotted,
    /// 16 px dashes.
    Long,
}

/// The dash patterns, in order.
pub const DASHES: [Dash; 4] = [Dash::Solid, Dash::Dashed, Dash::Dotted, Dash::Long];

impl Dash {
    /// Dash length and gap (px), `None` for a solid line.
    pub fn pattern(self) -> Option<(u32, u32)> {
        match self {
            Dash::Solid => None,
            Dash::Dashed => Some((8, 5)),
            Dash::Dotted => Some((2, 5)),
            Dash::Long => Some((16, 6)),
        }
    }
}

/// A point marker.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Mark {
    /// A filled circle.
    Circle,
    /// A filled triangle.
    Triangle,
    /// A filled square.
    Square,
    /// A filled diamond.
    Diamond,
    /// An × cross.
    Cross,
}

/// The markers, in order.
pub const MARKS: [Mark; 5] = [Mark::Circle, Mark::Triangle, Mark::Square, Mark::Diamond, Mark::Cross];

/// A series' colour, line pattern and marker.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SeriesStyle {
    /// Colour.
    pub colour: RGBColor,
    /// Line pattern.
    pub dash: Dash,
    /// Marker.
    pub mark: Mark,
}

/// The style of the `j`-th series (0-based): colour, pattern and marker each cycle through
/// lists of coprime lengths (7, 4, 5), so that no two of the first 140 series look alike and
/// the first seven differ in all three. With `colour` given (one colour per strategy), pattern
/// and marker alone tell the first 20 series apart.
pub fn series_style(j: usize, colour: Option<RGBColor>) -> SeriesStyle {
    SeriesStyle {
        colour: colour.unwrap_or(SERIES[j % SERIES.len()]),
        dash: DASHES[j % DASHES.len()],
        mark: MARKS[j % MARKS.len()],
    }
}

/// Draws the marker `mark` centred at the pixel `(x, y)` of `area`, `r` px across half.
pub fn draw_mark<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    (x, y): (i32, i32),
    mark: Mark,
    colour: RGBColor,
    r: i32,
) -> Result<(), String> {
    let e = super::err;
    let r = pxi(r);
    match mark {
        Mark::Circle => area.draw(&Circle::new((x, y), r as u32, colour.filled())).map_err(e),
        Mark::Triangle => area.draw(&TriangleMarker::new((x, y), r + pxi(1), colour.filled())).map_err(e),
        Mark::Square => {
            let h = r * 4 / 5;
            area.draw(&Rectangle::new([(x - h, y - h), (x + h, y + h)], colour.filled())).map_err(e)
        }
        Mark::Diamond => area
            .draw(&Polygon::new(
                vec![(x, y - r - 1), (x + r + 1, y), (x, y + r + 1), (x - r - 1, y)],
                colour.filled(),
            ))
            .map_err(e),
        Mark::Cross => area.draw(&Cross::new((x, y), r, colour.stroke_width(px(2)))).map_err(e),
    }
}

/// Draws `points` as a line in `style`'s colour and pattern, `width` px wide, with its marker on
/// every point.
pub fn draw_styled<'a, DB: DrawingBackend, X, Y>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    points: &[(f64, f64)],
    style: SeriesStyle,
    width: u32,
) -> Result<(), String>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let line = style.colour.stroke_width(px(width));
    match style.dash.pattern() {
        None => chart.draw_series(LineSeries::new(points.iter().copied(), line)).map(|_| ()),
        Some((dash, gap)) => chart
            .draw_series(DashedLineSeries::new(points.iter().copied(), px(dash), px(gap), line))
            .map(|_| ()),
    }
    .map_err(super::err)?;
    let area = chart.plotting_area().strip_coord_spec();
    for &p in points {
        let (x, y) = chart.backend_coord(&p);
        // Backend coordinates are the root's; the stripped area draws in its own.
        let (ox, oy) = area.get_base_pixel();
        draw_mark(&area, (x - ox, y - oy), style.mark, style.colour, 5)?;
    }
    Ok(())
}

/// Colour of a strategy, the same in every plot.
pub fn strategy_colour(name: &str) -> RGBColor {
    match name {
        "newton" => RGBColor(213, 94, 0),
        "p-step" => RGBColor(204, 121, 167),
        "damped" => RGBColor(0, 114, 178),
        _ => RGBColor(0, 158, 115),
    }
}

const SUPERSCRIPT: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];

/// `10⁵`, `10⁻³`.
pub fn power_of_ten(exponent: i32) -> String {
    let digits: String =
        exponent.unsigned_abs().to_string().chars().map(|c| SUPERSCRIPT[c as usize - 48]).collect();
    format!("10{}{digits}", if exponent < 0 { "⁻" } else { "" })
}

/// Tick label of a log axis: `10⁵` on powers of ten, `2·10⁵` between.
pub fn log_tick(v: &f64) -> String {
    if !(v.is_finite() && *v > 0.0) {
        return String::new();
    }
    let e = v.log10().floor();
    let mantissa = v / 10f64.powf(e);
    let (mantissa, e) = if mantissa > 9.9995 { (1.0, e + 1.0) } else { (mantissa, e) };
    if (mantissa - 1.0).abs() < 1e-3 {
        power_of_ten(e as i32)
    } else {
        format!("{}·{}", trim(mantissa, 1), power_of_ten(e as i32))
    }
}

/// A compact number: `1e5` style for stiffnesses in captions.
pub fn short_sci(v: f64) -> String {
    let e = v.log10().floor();
    let m = v / 10f64.powf(e);
    if (m - 1.0).abs() < 1e-6 {
        format!("1e{}", e as i32)
    } else {
        format!("{}e{}", trim(m, 2), e as i32)
    }
}

/// `v` with at most `decimals` decimals and no trailing zeros.
pub fn trim(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// A logarithmic range padded by `pad` (a factor) around the finite positive values given.
pub fn log_bounds(values: impl IntoIterator<Item = f64>, pad: f64) -> Range<f64> {
    let (lo, hi) = values
        .into_iter()
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0.0_f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if !(lo.is_finite() && hi > 0.0) {
        return 1.0..10.0;
    }
    let (lo, hi) = (lo / pad, hi * pad);
    // At least one decade, so that the axis carries a labelled power of ten.
    if hi / lo < 10.0 {
        let mid = (lo * hi).sqrt();
        return mid / 10f64.sqrt()..mid * 10f64.sqrt();
    }
    lo..hi
}

/// Labelled ticks of a logarithmic axis over `range`: every power of ten in it, and 2· and 5·
/// when it spans fewer than four decades, so that every part of the axis carries a number
/// (plotters' own choice left stretches of a decade unlabelled, or crowded one with nine labels).
/// Second: the unlabelled grid, every 1…9· multiple.
pub fn log_ticks(range: &Range<f64>) -> (Vec<f64>, Vec<f64>) {
    let (lo, hi) = (range.start.min(range.end), range.start.max(range.end));
    if !(lo > 0.0 && hi.is_finite()) {
        return (Vec::new(), Vec::new());
    }
    let (first, last) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let inside = |v: &f64| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9);
    let multiples = |ms: &[f64]| -> Vec<f64> {
        (first..=last).flat_map(|e| ms.iter().map(move |m| m * 10f64.powi(e))).filter(inside).collect()
    };
    let labelled = if last - first <= 4 { multiples(&[1.0, 2.0, 5.0]) } else { multiples(&[1.0]) };
    (labelled, multiples(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]))
}

/// A symmetric logarithmic axis, y ↦ sign(y)·log₁₀(1 + |y|): linear near 0 (the ±2σ band stays
/// visible), logarithmic far out (a 1000σ residual still fits).
#[derive(Debug, Clone)]
pub struct SymLog {
    /// Lower end (data units).
    pub lo: f64,
    /// Upper end (data units).
    pub hi: f64,
}

impl SymLog {
    /// The transform.
    pub fn t(v: f64) -> f64 {
        v.signum() * (1.0 + v.abs()).log10()
    }

    /// A range covering `[lo, hi]` and at least ±3, with a little room.
    pub fn covering(lo: f64, hi: f64) -> Self {
        let room = |v: f64| 10f64.powf(Self::t(v.max(3.0)) * 1.08) - 1.0;
        Self { lo: -room(-lo), hi: room(hi) }
    }
}

impl Ranged for SymLog {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let (a, b) = (Self::t(self.lo), Self::t(self.hi));
        let r = (Self::t(*value) - a) / (b - a);
        limit.0 + (r * f64::from(limit.1 - limit.0)).round() as i32
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        let mut magnitudes = vec![1.0, 2.0];
        let mut decade = 10.0;
        while decade <= self.hi.abs().max(self.lo.abs()) {
            magnitudes.push(decade);
            decade *= 10.0;
        }
        let mut points = vec![0.0];
        for m in magnitudes {
            points.extend([-m, m]);
        }
        points.retain(|v| (self.lo..=self.hi).contains(v));
        // ±1 crowds ±2 once the axis reaches beyond ±10.
        if self.hi.abs().max(self.lo.abs()) > 10.0 || points.len() > hint.max_num_points().max(5) {
            points.retain(|v| v.abs() != 1.0);
        }
        points.sort_by(f64::total_cmp);
        points
    }

    fn range(&self) -> Range<f64> {
        self.lo..self.hi
    }
}

/// A chart over x (m) and a normalised displacement on fixed ticks: what [`shaft_chart`] builds.
pub type ShaftChart<'a, DB> =
    ChartContext<'a, DB, Cartesian2d<plotters::coord::types::RangedCoordf64, FixedTicks>>;

/// A chart along a shaft, its grid drawn: x the position `x` (m) with 4 % room at each end, y a
/// normalised displacement ticked at −1, −0.5, 0, 0.5, 1 only, from −1.75 (room for the bearing
/// labels under the shaft) to `top` (room for the disk labels over it). Returns the chart and the
/// room added at each end (the unit the markers of disks are sized in).
pub fn shaft_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, plotters::coord::Shift>,
    x: Range<f64>,
    top: f64,
    x_label: &str,
    y_label: &str,
) -> Result<(ShaftChart<'a, DB>, f64), String> {
    let pad = (x.end - x.start) * 0.04;
    let y_ticks = vec![-1.0, -0.5, 0.0, 0.5, 1.0];
    let mut chart = ChartBuilder::on(area)
        .margin(px(20))
        .margin_top(px(5))
        .x_label_area_size(px(60))
        .y_label_area_size(px(80))
        .build_cartesian_2d(x.start - pad..x.end + pad, FixedTicks { lo: -1.75, hi: top, ticks: y_ticks })
        .map_err(super::err)?;
    let mut mesh = chart.configure_mesh();
    grid(axes(&mut mesh, x_label, y_label), 0.4)
        .x_label_formatter(&|v: &f64| trim(*v, 3))
        .y_label_formatter(&|v: &f64| trim(*v, 1))
        .draw()
        .map_err(super::err)?;
    Ok((chart, pad))
}

/// A linear axis over `lo..hi` with ticks only at `ticks`: every tick drawn is one the chart
/// labels (plotters' own choice spreads ticks over the whole range, also where the axis holds
/// no values to read).
#[derive(Debug, Clone)]
pub struct FixedTicks {
    /// Lower end.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
    /// The ticks, inside the range.
    pub ticks: Vec<f64>,
}

impl Ranged for FixedTicks {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let r = (value - self.lo) / (self.hi - self.lo);
        limit.0 + (r * f64::from(limit.1 - limit.0)).round() as i32
    }

    fn key_points<Hint: KeyPointHint>(&self, _hint: Hint) -> Vec<f64> {
        self.ticks.iter().copied().filter(|t| (self.lo..=self.hi).contains(t)).collect()
    }

    fn range(&self) -> Range<f64> {
        self.lo..self.hi
    }
}

/// Tick label of the symmetric-log residual axis: `0`, `±2σ`, `+1000σ`.
pub fn sigma_tick(v: &f64) -> String {
    if *v == 0.0 {
        "0".to_string()
    } else {
        let magnitude = trim(v.abs(), 0);
        format!("{}{magnitude}σ", if *v < 0.0 { "−" } else { "+" })
    }
}

/// A legend entry's symbol.
pub enum Swatch {
    /// A filled box.
    Box(RGBColor),
    /// A solid line.
    Line(RGBColor),
    /// A dashed line.
    Dashed(RGBColor),
    /// A series' line pattern with its marker.
    Series(SeriesStyle),
    /// A thin dashed guide line.
    Guide,
    /// The target marker (a cross).
    Target,
    /// Text only.
    None,
}

/// Draws one swatch at `(x, y)` (top-left of a 20 px high row); returns its width.
fn swatch<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    (x, y): (i32, i32),
    swatch: &Swatch,
) -> Result<i32, String> {
    let e = super::err;
    let p = pxi;
    let mid = y + p(10);
    match swatch {
        Swatch::Box(c) => {
            area.draw(&Rectangle::new([(x, y + p(3)), (x + p(16), y + p(17))], c.filled())).map_err(e)?;
            area.draw(&Rectangle::new([(x, y + p(3)), (x + p(16), y + p(17))], GUIDE.stroke_width(px(1))))
                .map_err(e)?;
            Ok(p(24))
        }
        Swatch::Line(c) => {
            area.draw(&PathElement::new(vec![(x, mid), (x + p(26), mid)], c.stroke_width(px(3))))
                .map_err(e)?;
            Ok(p(34))
        }
        Swatch::Dashed(c) => {
            for (a, b) in [(0, 8), (13, 26)] {
                area.draw(&PathElement::new(vec![(x + p(a), mid), (x + p(b), mid)], c.stroke_width(px(3))))
                    .map_err(e)?;
            }
            Ok(p(34))
        }
        Swatch::Series(st) => {
            let line = st.colour.stroke_width(px(3));
            let segments: Vec<(i32, i32)> = match st.dash.pattern() {
                None => vec![(0, 34)],
                Some((dash, gap)) => {
                    let (dash, gap) = (dash as i32, gap as i32);
                    (0..)
                        .map(|k| k * (dash + gap))
                        .take_while(|a| *a < 34)
                        .map(|a| (a, (a + dash).min(34)))
                        .collect()
                }
            };
            for (a, b) in segments {
                area.draw(&PathElement::new(vec![(x + p(a), mid), (x + p(b), mid)], line)).map_err(e)?;
            }
            draw_mark(area, (x + p(17), mid), st.mark, st.colour, 5)?;
            Ok(p(44))
        }
        Swatch::Guide => {
            for (a, b) in [(0, 4), (9, 13), (18, 22)] {
                area.draw(&PathElement::new(vec![(x + p(a), mid), (x + p(b), mid)], INK.stroke_width(px(1))))
                    .map_err(e)?;
            }
            Ok(p(34))
        }
        Swatch::Target => {
            area.draw(&Cross::new((x + p(8), mid), p(6), INK.stroke_width(px(3)))).map_err(e)?;
            Ok(p(24))
        }
        Swatch::None => Ok(0),
    }
}

/// Draws `entries` in one row starting at `(x, y)` (top-left); returns the x after the last.
pub fn legend_row<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    (mut x, y): (i32, i32),
    entries: &[(Swatch, String)],
) -> Result<i32, String> {
    let style = text(LEGEND, INK);
    for (sw, label) in entries {
        x += swatch(area, (x, y), sw)?;
        area.draw(&Text::new(label.clone(), (x, y + pxi(2)), style.clone())).map_err(super::err)?;
        let (w, _) = area.estimate_text_size(label, &style).map_err(super::err)?;
        x += w as i32 + pxi(26);
    }
    Ok(x)
}

/// Draws `entries` one per line starting at `(x, y)` (top-left); returns the y after the last.
pub fn legend_column<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    (x, mut y): (i32, i32),
    entries: &[(Swatch, String)],
) -> Result<i32, String> {
    let style = text(LEGEND, INK);
    for (sw, label) in entries {
        let w = swatch(area, (x, y), sw)?;
        area.draw(&Text::new(label.clone(), (x + w, y + pxi(2)), style.clone())).map_err(super::err)?;
        y += pxi(26);
    }
    Ok(y)
}

/// The figure title, centred in the top `height` pixels of `area`; returns the rest.
pub fn title<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    height: u32,
) -> Result<DrawingArea<DB, plotters::coord::Shift>, String> {
    let (head, rest) = area.split_vertically(px(height));
    let (w, _) = head.dim_in_pixel();
    head.draw(&Text::new(
        title.to_string(),
        (w as i32 / 2, pxi(30)),
        text(TITLE, INK).pos(Pos::new(HPos::Center, VPos::Center)),
    ))
    .map_err(super::err)?;
    Ok(rest)
}

/// The axis titles in the axis font and the tick labels in the tick font: every chart's mesh
/// starts here, the rest (formatters, grid lines) is the chart's own.
pub fn axes<'m, 'a, 'b, X: Ranged, Y: Ranged, DB: DrawingBackend>(
    mesh: &'m mut MeshStyle<'a, 'b, X, Y, DB>,
    x: impl Into<String>,
    y: impl Into<String>,
) -> &'m mut MeshStyle<'a, 'b, X, Y, DB> {
    mesh.x_desc(x)
        .y_desc(y)
        .axis_desc_style(font(AXIS))
        .label_style(font(TICK))
        .axis_style(BLACK.stroke_width(px(1)))
        .set_all_tick_mark_size(px(5))
}

/// Minor grid lines in the light grey at `minor_alpha`, major ones in the light grey.
pub fn grid<'m, 'a, 'b, X: Ranged, Y: Ranged, DB: DrawingBackend>(
    mesh: &'m mut MeshStyle<'a, 'b, X, Y, DB>,
    minor_alpha: f64,
) -> &'m mut MeshStyle<'a, 'b, X, Y, DB> {
    mesh.light_line_style(LIGHT.mix(minor_alpha).stroke_width(px(1)))
        .bold_line_style(LIGHT.stroke_width(px(1)))
}

/// Draws the series legend at `position` in the shared look (legend font, a light box).
pub fn legend<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
) -> super::DrawResult {
    chart
        .configure_series_labels()
        .position(position)
        .label_font(font(LEGEND))
        .background_style(WHITE.mix(0.9))
        .border_style(GUIDE.stroke_width(px(1)))
        .margin(px(12))
        .legend_area_size(px(30))
        .draw()
        .map_err(super::err)
}
