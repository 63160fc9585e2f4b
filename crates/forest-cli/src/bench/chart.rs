//! Charts of the benchmark suites with plotters: each chart is written as PNG and SVG from one
//! drawing function. Logarithmic axes plot `log10` of the values on a linear axis with labels
//! turned back into values (one code path for both kinds of axis).

use std::path::Path;

use anyhow::{Result, anyhow};
use plotters::coord::Shift;
use plotters::prelude::*;

/// One named series of points.
#[derive(Clone, Debug, Default)]
pub struct Series {
    /// Legend entry.
    pub name: String,
    /// Points in data units.
    pub points: Vec<(f64, f64)>,
    /// Join the points in order with a line (else markers only).
    pub line: bool,
    /// Draw the series' Pareto front (smaller x and smaller y are better) as a line.
    pub front: bool,
}

impl Series {
    /// A series joined by a line, named `name`, with `points` (data units).
    pub fn line(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            name: name.into(),
            points,
            line: true,
            front: false,
        }
    }
}

/// A 2D chart.
#[derive(Clone, Debug, Default)]
pub struct Chart {
    /// Caption.
    pub title: String,
    /// X axis label.
    pub x_label: String,
    /// Y axis label.
    pub y_label: String,
    /// Logarithmic x axis (values must be positive; others are dropped).
    pub log_x: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
    /// The data.
    pub series: Vec<Series>,
}

/// The points no other point beats in both coordinates (smaller is better), by ascending x.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut p: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .collect();
    p.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut front: Vec<(f64, f64)> = Vec::new();
    for q in p {
        if front.last().is_none_or(|l| q.1 < l.1) {
            front.push(q);
        }
    }
    front
}

fn register_font() {
    static FONT: std::sync::Once = std::sync::Once::new();
    FONT.call_once(|| {
        // Registration only fails on a malformed font, which the embedded one is not.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, crate::FONT);
    });
}

const SIZE: (u32, u32) = (900, 600);

/// Series colours, in series order (methods are always added in the same order, so a method
/// keeps its colour across charts).
const PALETTE: [(u8, u8, u8); 12] = [
    (214, 39, 40),
    (255, 127, 14),
    (40, 40, 40),
    (31, 119, 180),
    (44, 160, 44),
    (148, 103, 189),
    (140, 86, 75),
    (23, 190, 207),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (0, 0, 128),
];

/// A method keeps one colour on every chart (series named after it, or after it and a colon);
/// other series take the palette in order.
fn colour_of(name: &str, k: usize) -> (u8, u8, u8) {
    let method = name.split(':').next().unwrap_or(name);
    match method {
        "quads" => PALETTE[0],
        "impostor" => PALETTE[1],
        "geometry" | "geometry-unsorted" => PALETTE[2],
        "stochastic" => PALETTE[3],
        "lods" => PALETTE[4],
        "hybrid" => PALETTE[5],
        _ => PALETTE[k % PALETTE.len()],
    }
}

fn axis(v: f64, log: bool) -> Option<f64> {
    if !v.is_finite() {
        None
    } else if log {
        (v > 0.0).then(|| v.log10())
    } else {
        Some(v)
    }
}

fn label(v: f64, log: bool) -> String {
    let x = if log { 10f64.powf(v) } else { v };
    let a = x.abs();
    if log && (1e-4..1e5).contains(&a) {
        // Two significant digits: 0.25, 0.32, …, 25, 32, 40, 50, 63, …
        let e = a.log10().floor() as i32 - 1;
        let p = 10f64.powi(e);
        return format!("{:.*}", (-e).max(0) as usize, (x / p).round() * p);
    }
    if a == 0.0 {
        "0".into()
    } else if !(1e-3..1e5).contains(&a) {
        format!("{x:.0e}")
    } else if a >= 100.0 {
        format!("{x:.0}")
    } else if a >= 1.0 {
        format!("{x:.3}")
            .trim_end_matches('0')
            .trim_end_matches('.')
            .into()
    } else {
        format!("{x:.4}").trim_end_matches('0').into()
    }
}

/// The largest magnitude an axis reaches; data beyond it is drawn at the edge.
const AXIS_LIMIT: f64 = 1e300;

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, c: &Chart) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow!("drawing a chart: {e:?}");
    root.fill(&WHITE).map_err(err)?;
    let pts: Vec<Vec<(f64, f64)>> = c
        .series
        .iter()
        .map(|s| {
            s.points
                .iter()
                .filter_map(|&(x, y)| Some((axis(x, c.log_x)?, axis(y, c.log_y)?)))
                // Non-finite points are left out, the rest kept within the axes' reach (a
                // point beyond an axis overflows the plotting's pixel arithmetic).
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .map(|(x, y)| {
                    let clamp = |v: f64| v.clamp(-AXIS_LIMIT, AXIS_LIMIT);
                    (clamp(x), clamp(y))
                })
                .collect()
        })
        .collect();
    let all: Vec<&(f64, f64)> = pts.iter().flatten().collect();
    // Axes hold any finite data: the extremes are clamped to ±AXIS_LIMIT, and spans are
    // taken as differences of scaled ends, so no step overflows.
    let range = |f: fn(&(f64, f64)) -> f64| {
        let finite = all.iter().map(|p| f(p)).filter(|v| v.is_finite());
        let lo = finite
            .clone()
            .fold(f64::INFINITY, f64::min)
            .max(-AXIS_LIMIT);
        let hi = finite.fold(f64::NEG_INFINITY, f64::max).min(AXIS_LIMIT);
        if lo > hi {
            return 0.0..1.0;
        }
        let pad = (hi * 0.08 - lo * 0.08).max(if lo.abs() > 0.0 { lo.abs() * 0.05 } else { 0.5 });
        (lo - pad)..(hi + pad)
    };
    // Room above the data for the legend.
    let y_range = {
        let r = range(|p| p.1);
        let share = 0.05 * c.series.len() as f64 + 0.03;
        let legend = r.end * share - r.start * share;
        r.start..(r.end + legend).min(f64::MAX)
    };
    let mut chart = ChartBuilder::on(&root)
        .caption(&c.title, ("sans-serif", 22))
        .margin(14)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(range(|p| p.0), y_range)
        .map_err(err)?;
    let (lx, ly) = (c.log_x, c.log_y);
    chart
        .configure_mesh()
        .x_desc(&c.x_label)
        .y_desc(&c.y_label)
        .x_label_formatter(&|v| label(*v, lx))
        .y_label_formatter(&|v| label(*v, ly))
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    for (k, (s, p)) in c.series.iter().zip(&pts).enumerate() {
        let (r, g, b) = colour_of(&s.name, k);
        let colour = RGBColor(r, g, b);
        if s.line {
            chart
                .draw_series(LineSeries::new(p.iter().copied(), colour.stroke_width(2)))
                .map_err(err)?;
        }
        if s.front {
            chart
                .draw_series(LineSeries::new(pareto_front(p), colour.stroke_width(2)))
                .map_err(err)?;
        }
        chart
            .draw_series(p.iter().map(|&q| Circle::new(q, 4, colour.filled())))
            .map_err(err)?
            .label(&s.name)
            .legend(move |(x, y)| Circle::new((x + 8, y), 5, colour.filled()));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 15))
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}

/// Write `stem.png` and `stem.svg` (each to a temporary name, then renamed).
pub fn save(c: &Chart, stem: &Path) -> Result<()> {
    register_font();
    let svg = stem.with_extension("svg");
    forest_format::atomic::write_with(&svg, |tmp| {
        draw(SVGBackend::new(tmp, SIZE).into_drawing_area(), c)
    })?;
    let mut buf = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    draw(
        BitMapBackend::with_buffer(&mut buf, SIZE).into_drawing_area(),
        c,
    )?;
    let png = stem.with_extension("png");
    let img = image::RgbImage::from_raw(SIZE.0, SIZE.1, buf)
        .ok_or_else(|| anyhow!("chart buffer size"))?;
    forest_format::atomic::write_with(&png, |tmp| {
        img.save_with_format(tmp, image::ImageFormat::Png)
    })?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pareto_front_keeps_only_unbeaten_points() {
        let p = [
            (1.0, 5.0),
            (2.0, 3.0),
            (3.0, 4.0),
            (4.0, 1.0),
            (2.5, 3.0),
            (f64::NAN, 0.0),
        ];
        assert_eq!(pareto_front(&p), vec![(1.0, 5.0), (2.0, 3.0), (4.0, 1.0)]);
        assert!(pareto_front(&[]).is_empty());
    }

    #[test]
    fn charts_are_written_as_png_and_svg() {
        let dir = tempfile::tempdir().unwrap();
        let c = Chart {
            title: "Caption of the test".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            log_x: true,
            series: vec![Series {
                name: "a".into(),
                points: vec![(1.0, 1.0), (10.0, 2.0), (0.0, 3.0)],
                line: true,
                front: true,
            }],
            ..Default::default()
        };
        save(&c, &dir.path().join("c")).unwrap();
        let png = image::open(dir.path().join("c.png")).unwrap();
        assert_eq!((png.width(), png.height()), SIZE);
        // Something besides the white background was drawn.
        assert!(png.to_rgb8().pixels().any(|p| p.0 != [255, 255, 255]));
        let svg = std::fs::read_to_string(dir.path().join("c.svg")).unwrap();
        assert!(
            svg.contains("<svg") && svg.contains("Caption of the test"),
            "caption in the SVG"
        );
    }

    /// Any finite data is drawn, extremes included (an axis padded by its span once
    /// overflowed to infinity and never finished); non-finite points are left out.
    #[test]
    fn extreme_finite_values_are_charted() {
        let dir = tempfile::tempdir().unwrap();
        for points in [
            vec![(0.0, 1e308), (1.0, -1e308), (2.0, f64::NAN)],
            vec![(f64::MAX, f64::MAX), (-f64::MAX, 0.0)],
            vec![(1.0, 5.0), (1.0, 5.0)],
            vec![(f64::INFINITY, 1.0)],
        ] {
            let c = Chart {
                title: "extremes".into(),
                series: (0..10)
                    .map(|k| Series {
                        name: format!("s{k}"),
                        points: points.clone(),
                        line: true,
                        front: true,
                    })
                    .collect(),
                ..Default::default()
            };
            save(&c, &dir.path().join("x")).unwrap();
            assert!(dir.path().join("x.png").is_file());
        }
    }

    /// A value as any results may hold it: any float (NaN, infinities, subnormals, the
    /// largest), or an ordinary figure.
    fn value() -> impl proptest::strategy::Strategy<Value = f64> {
        use proptest::prelude::*;
        prop_oneof![
            any::<f64>(),
            -1e6f64..1e6,
            prop::sample::select(vec![0.0, f64::MAX, -f64::MAX, f64::MIN_POSITIVE, 1e-320]),
        ]
    }

    proptest::proptest! {
        // Each case draws a chart: the count of cases bounds the test, not a clock.
        #![proptest_config(proptest::test_runner::Config::with_cases(48))]

        /// Any values, on linear or log axes, are drawn without a panic and the drawing
        /// returns (the padding that once overflowed made it loop for good).
        #[test]
        fn any_values_are_drawn(
            series in proptest::collection::vec(
                proptest::collection::vec((value(), value()), 0..6), 1..4),
            log_x in proptest::bool::ANY,
            log_y in proptest::bool::ANY,
        ) {
            let c = Chart {
                title: "any".into(),
                log_x,
                log_y,
                series: series
                    .into_iter()
                    .enumerate()
                    .map(|(k, points)| Series {
                        name: format!("s{k}"),
                        points,
                        line: k % 2 == 0,
                        front: true,
                    })
                    .collect(),
                ..Default::default()
            };
            let mut buf = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
            register_font();
            draw(BitMapBackend::with_buffer(&mut buf, SIZE).into_drawing_area(), &c).unwrap();
        }
    }
}
