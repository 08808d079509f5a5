//! Small dependency-free SVG charts.

use eigenfit_core::discovery::DiscoveryReport;
use std::fmt::Write;

/// Bar chart of (model − measured)/σ per mode, before and after the named effect, over the
/// ±2σ noise band.
pub fn discovery(r: &DiscoveryReport, title: &str) -> String {
    let (w, h, left, top, bottom) = (720.0, 420.0, 70.0, 50.0, 60.0);
    let plot_h = h - top - bottom;
    let span = r
        .modes
        .iter()
        .flat_map(|m| [m.normalised_before().abs(), m.normalised_after().abs()])
        .fold(3.0_f64, f64::max)
        .ceil();
    let y = |v: f64| top + plot_h / 2.0 - v / span * plot_h / 2.0;
    let n = r.modes.len().max(1) as f64;
    let slot = (w - left - 20.0) / n;
    let mut s = String::new();
    let _ = write!(
        s,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="12">
<rect width="100%" height="100%" fill="white"/>
<text x="{cx}" y="24" text-anchor="middle" font-size="15">{title}: residual per mode before and after discovery</text>
<rect x="{left}" y="{b_top}" width="{pw}" height="{b_h}" fill="#dfe8f5"/>
<line x1="{left}" y1="{y0}" x2="{right}" y2="{y0}" stroke="black"/>
<line x1="{left}" y1="{top}" x2="{left}" y2="{ybot}" stroke="black"/>
<text x="18" y="{ymid}" transform="rotate(-90 18 {ymid})" text-anchor="middle">(model − measured) / σ</text>
<text x="{cx}" y="{xl}" text-anchor="middle">mode</text>
"##,
        cx = w / 2.0,
        b_top = y(2.0),
        pw = w - left - 20.0,
        b_h = y(-2.0) - y(2.0),
        y0 = y(0.0),
        right = w - 20.0,
        ybot = h - bottom,
        ymid = top + plot_h / 2.0,
        xl = h - 15.0,
    );
    for v in [-span, -2.0, 2.0, span] {
        let _ =
            writeln!(s, r#"<text x="{}" y="{}" text-anchor="end">{v:+.0}σ</text>"#, left - 6.0, y(v) + 4.0);
    }
    for (i, m) in r.modes.iter().enumerate() {
        let x0 = left + slot * i as f64 + slot * 0.15;
        let bw = slot * 0.33;
        for (j, (v, colour, label)) in
            [(m.normalised_before(), "#9a9a9a", "before"), (m.normalised_after(), "#1f5fbf", "after")]
                .iter()
                .enumerate()
        {
            let (ya, yb) = (y(v.max(0.0)), y(v.min(0.0)));
            let _ = writeln!(
                s,
                r#"<rect class="{label}" x="{:.1}" y="{ya:.1}" width="{bw:.1}" height="{:.1}" fill="{colour}"><title>mode {} {label}: {v:+.2}σ</title></rect>"#,
                x0 + j as f64 * bw,
                (yb - ya).max(0.5),
                m.mode + 1
            );
        }
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{}" text-anchor="middle">{}</text>"#,
            x0 + bw,
            h - bottom + 18.0,
            m.mode + 1
        );
    }
    let legend = match &r.selected {
        Some(sel) => format!("after: with {}", sel.label),
        None => "after: nothing added".to_string(),
    };
    let _ = write!(
        s,
        r##"<rect x="{lx}" y="36" width="12" height="12" fill="#9a9a9a"/><text x="{tx}" y="46">before (calibrated nominal model)</text>
<rect x="{lx2}" y="36" width="12" height="12" fill="#1f5fbf"/><text x="{tx2}" y="46">{legend}</text>
<text x="{right}" y="{band}" text-anchor="end" fill="#5a7fb5">±2σ noise band</text>
</svg>
"##,
        lx = left + 10.0,
        tx = left + 26.0,
        lx2 = left + 280.0,
        tx2 = left + 296.0,
        right = w - 24.0,
        band = y(2.0) - 4.0,
    );
    s
}
