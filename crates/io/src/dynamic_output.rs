//! Outputs of a dynamic-curve run: the final curve and the frames of its evolution as CSV, and a
//! picture in the manner of the paper's Figs. 3–5 (initial, intermediate and final curve with the
//! data points) as SVG.

use crate::dynamic::CurveFrame;
use crate::{Error, Result, Vec3};
use std::fmt::Write as _;
use std::io::Write;

const NAMES: [&str; 3] = ["x", "y", "z"];

fn check_dim(dim: usize) -> Result<()> {
    if (1..=3).contains(&dim) {
        Ok(())
    } else {
        Err(Error::invalid(format!(
            "{dim} components; 1 to 3 can be written"
        )))
    }
}

fn io(e: std::io::Error) -> Error {
    Error::from(e)
}

fn row(w: &mut dyn Write, lead: &[f64], p: &Vec3, dim: usize) -> Result<()> {
    let mut line = String::with_capacity(96);
    for (k, v) in lead.iter().chain(p.iter().take(dim)).enumerate() {
        if k > 0 {
            line.push(',');
        }
        // Rust prints the shortest decimal that reads back to the same f64.
        let _ = write!(line, "{v}");
    }
    line.push('\n');
    w.write_all(line.as_bytes()).map_err(io)
}

/// Writes `u,x[,y[,z]]` (first `dim` components), one row per node `u_j = j/J`, full precision.
pub fn write_curve_csv(nodes: &[Vec3], dim: usize, w: &mut dyn Write) -> Result<()> {
    check_dim(dim)?;
    if nodes.len() < 2 {
        return Err(Error::invalid("a curve needs at least 2 nodes"));
    }
    let header = format!("u,{}\n", NAMES[..dim].join(","));
    w.write_all(header.as_bytes()).map_err(io)?;
    let jn = (nodes.len() - 1) as f64;
    for (j, p) in nodes.iter().enumerate() {
        row(w, &[j as f64 / jn], p, dim)?;
    }
    Ok(())
}

/// Writes `step,t,u,x[,y[,z]]`, the nodes of every frame in order, full precision.
pub fn write_frames_csv(frames: &[CurveFrame], dim: usize, w: &mut dyn Write) -> Result<()> {
    write_frames_header(dim, w)?;
    for f in frames {
        write_frame_rows(f, dim, w)?;
    }
    Ok(())
}

/// The header line of [`write_frames_csv`] (for writing frames as they come).
pub fn write_frames_header(dim: usize, w: &mut dyn Write) -> Result<()> {
    check_dim(dim)?;
    let header = format!("step,t,u,{}\n", NAMES[..dim].join(","));
    w.write_all(header.as_bytes()).map_err(io)
}

/// The rows of one frame in [`write_frames_csv`].
pub fn write_frame_rows(f: &CurveFrame, dim: usize, w: &mut dyn Write) -> Result<()> {
    check_dim(dim)?;
    let jn = (f.nodes.len().max(2) - 1) as f64;
    for (j, p) in f.nodes.iter().enumerate() {
        row(w, &[f.step as f64, f.time, j as f64 / jn], p, dim)?;
    }
    Ok(())
}

/// Picks the frames a picture shows: the first, the last and at most `intermediate` others,
/// evenly spread over the list.
pub fn pick_frames(frames: &[CurveFrame], intermediate: usize) -> Vec<&CurveFrame> {
    let n = frames.len();
    if n <= intermediate + 2 {
        return frames.iter().collect();
    }
    // Nearest index to k (n − 1)/(m + 1), m = intermediate.
    let m1 = intermediate + 1;
    let half = m1 / 2;
    let mut idx: Vec<usize> = (0..=m1).map(|k| (k * (n - 1) + half) / m1).collect();
    idx.dedup();
    idx.into_iter().map(|i| &frames[i]).collect()
}

/// An SVG picture (`width × height` pixels) of the curves of `frames` projected on the
/// `x, y` plane (`y` up; a curve with one component is drawn as the graph `(u, x)`): the first
/// frame dashed grey, the intermediate ones light blue, the last one dark red, and `points`
/// (interior data points) as circles, `ends` (end points) as squares. Equal scales on both axes,
/// drawn as a frame with round ticks and their values on the left and bottom sides (`x`, `y` or
/// `u`, `x` named at the ends), and a legend in the upper right corner naming the first and last
/// frames (step and time), the intermediate ones and the points.
pub fn svg_picture(
    frames: &[&CurveFrame],
    points: &[Vec3],
    ends: &[Vec3],
    dim: usize,
    width: u32,
    height: u32,
) -> Result<String> {
    use crate::render::{nice_step, nice_ticks, tick_label};
    check_dim(dim)?;
    if frames.is_empty() {
        return Err(Error::invalid("no frames to draw"));
    }
    let plane = |p: &Vec3, u: f64| -> (f64, f64) {
        if dim == 1 {
            (u, p[0])
        } else {
            (p[0], p[1])
        }
    };
    let mut all: Vec<(f64, f64)> = Vec::new();
    for f in frames {
        let jn = (f.nodes.len().max(2) - 1) as f64;
        all.extend(
            f.nodes
                .iter()
                .enumerate()
                .map(|(j, p)| plane(p, j as f64 / jn)),
        );
    }
    all.extend(points.iter().chain(ends).map(|p| plane(p, 0.0)));
    if let Some(bad) = all.iter().find(|(x, y)| !(x.is_finite() && y.is_finite())) {
        return Err(Error::invalid(format!(
            "cannot draw the non-finite point {bad:?}"
        )));
    }
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in &all {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    let (w, h) = (width as f64, height as f64);
    // The plot area: room for tick labels on the left and below.
    let (left, right, top, bottom) = (
        (0.1 * w).clamp(8.0, 80.0),
        (0.03 * w).clamp(4.0, 24.0),
        (0.04 * h).clamp(4.0, 24.0),
        (0.08 * h).clamp(8.0, 50.0),
    );
    let (pw, ph) = ((w - left - right).max(1.0), (h - top - bottom).max(1.0));
    let pad = 0.04 * pw.min(ph);
    let span = (x1 - x0).max(y1 - y0).max(f64::MIN_POSITIVE);
    let scale = ((pw - 2.0 * pad) / (x1 - x0).max(span * 1e-9))
        .min((ph - 2.0 * pad) / (y1 - y0).max(span * 1e-9));
    let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
    let (mx, my) = (left + pw / 2.0, top + ph / 2.0);
    let map = |(x, y): (f64, f64)| (mx + (x - cx) * scale, my - (y - cy) * scale);
    // What the plot area shows, in data units.
    let (vx0, vx1) = (cx - pw / 2.0 / scale, cx + pw / 2.0 / scale);
    let (vy0, vy1) = (cy - ph / 2.0 / scale, cy + ph / 2.0 / scale);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\" \
         viewBox=\"0 0 {width} {height}\" font-family=\"sans-serif\" font-size=\"12\">"
    );
    let _ = writeln!(s, "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>");
    // Axes: the frame, ticks and their values.
    let _ = writeln!(
        s,
        "<rect class=\"frame\" x=\"{left:.2}\" y=\"{top:.2}\" width=\"{pw:.2}\" height=\"{ph:.2}\" \
         fill=\"none\" stroke=\"#444444\" stroke-width=\"1\"/>"
    );
    let (xname, yname) = if dim == 1 { ("u", "x") } else { ("x", "y") };
    let xstep = nice_step(vx0, vx1);
    for t in nice_ticks(vx0, vx1) {
        let (px, _) = map((t, cy));
        let yb = top + ph;
        let _ = writeln!(
            s,
            "<line x1=\"{px:.2}\" y1=\"{yb:.2}\" x2=\"{px:.2}\" y2=\"{:.2}\" stroke=\"#444444\"/>\
             <text class=\"tick-x\" x=\"{px:.2}\" y=\"{:.2}\" text-anchor=\"middle\">{}</text>",
            yb + 5.0,
            yb + 18.0,
            tick_label(t, xstep)
        );
    }
    let ystep = nice_step(vy0, vy1);
    for t in nice_ticks(vy0, vy1) {
        let (_, py) = map((cx, t));
        let _ = writeln!(
            s,
            "<line x1=\"{:.2}\" y1=\"{py:.2}\" x2=\"{left:.2}\" y2=\"{py:.2}\" stroke=\"#444444\"/>\
             <text class=\"tick-y\" x=\"{:.2}\" y=\"{:.2}\" text-anchor=\"end\">{}</text>",
            left - 5.0,
            left - 8.0,
            py + 4.0,
            tick_label(t, ystep)
        );
    }
    let _ = writeln!(
        s,
        "<text class=\"axis-name\" x=\"{:.2}\" y=\"{:.2}\" text-anchor=\"end\" font-style=\"italic\">{xname}</text>\
         <text class=\"axis-name\" x=\"{:.2}\" y=\"{:.2}\" text-anchor=\"end\" font-style=\"italic\">{yname}</text>",
        left + pw,
        top + ph + 34.0,
        left - 8.0,
        top + 12.0
    );
    let last = frames.len() - 1;
    let style = |k: usize| -> (&str, &str, f64) {
        if k == 0 && last > 0 {
            ("#888888", " stroke-dasharray=\"6 4\"", 1.2)
        } else if k == last {
            ("#b01818", "", 2.0)
        } else {
            ("#6fa8dc", "", 1.2)
        }
    };
    for (k, f) in frames.iter().enumerate() {
        let (stroke, extra, sw) = style(k);
        let jn = (f.nodes.len().max(2) - 1) as f64;
        let mut d = String::new();
        for (j, p) in f.nodes.iter().enumerate() {
            let (x, y) = map(plane(p, j as f64 / jn));
            let _ = write!(d, "{}{x:.2},{y:.2}", if j == 0 { "M" } else { " L" });
        }
        let _ = writeln!(
            s,
            "<path class=\"frame-curve\" d=\"{d}\" fill=\"none\" stroke=\"{stroke}\" stroke-width=\"{sw}\"{extra}>\
             <title>step {}, t = {}</title></path>",
            f.step, f.time
        );
    }
    let circle = |x: f64, y: f64| {
        format!(
            "<circle cx=\"{x:.2}\" cy=\"{y:.2}\" r=\"4\" fill=\"none\" stroke=\"black\" stroke-width=\"1.5\"/>"
        )
    };
    let square = |x: f64, y: f64| {
        format!(
            "<rect x=\"{:.2}\" y=\"{:.2}\" width=\"7\" height=\"7\" fill=\"black\"/>",
            x - 3.5,
            y - 3.5
        )
    };
    for p in points {
        let (x, y) = map(plane(p, 0.0));
        let _ = writeln!(s, "{}", circle(x, y));
    }
    for p in ends {
        let (x, y) = map(plane(p, 0.0));
        let _ = writeln!(s, "{}", square(x, y));
    }
    // The legend.
    let mut entries: Vec<(String, String)> = Vec::new();
    let sample = |k: usize| {
        let (stroke, extra, sw) = style(k);
        move |x: f64, y: f64| {
            format!(
                "<line x1=\"{:.2}\" y1=\"{y:.2}\" x2=\"{:.2}\" y2=\"{y:.2}\" stroke=\"{stroke}\" stroke-width=\"{sw}\"{extra}/>",
                x - 12.0,
                x + 12.0
            )
        }
    };
    let when = |f: &CurveFrame| format!("step {}, t = {}", f.step, short_time(f.time));
    if last > 0 {
        entries.push((format!("first: {}", when(frames[0])), sample(0)(0.0, 0.0)));
        if last > 1 {
            entries.push((format!("{} intermediate", last - 1), sample(1)(0.0, 0.0)));
        }
    }
    entries.push((
        format!(
            "{}: {}",
            if last > 0 { "last" } else { "curve" },
            when(frames[last])
        ),
        sample(last)(0.0, 0.0),
    ));
    if !points.is_empty() {
        entries.push(("data points".into(), circle(0.0, 0.0)));
    }
    if !ends.is_empty() {
        entries.push(("end points".into(), square(0.0, 0.0)));
    }
    let longest = entries
        .iter()
        .map(|(t, _)| t.chars().count())
        .max()
        .unwrap_or(0) as f64;
    let (lw, lh) = (40.0 + 7.0 * longest, 8.0 + 18.0 * entries.len() as f64);
    let (lx, ly) = (left + pw - lw - 6.0, top + 6.0);
    let _ = writeln!(
        s,
        "<g class=\"legend\"><rect x=\"{lx:.2}\" y=\"{ly:.2}\" width=\"{lw:.2}\" height=\"{lh:.2}\" \
         fill=\"white\" fill-opacity=\"0.85\" stroke=\"#aaaaaa\"/>"
    );
    for (k, (text, mark)) in entries.iter().enumerate() {
        let y = ly + 13.0 + 18.0 * k as f64;
        let x = lx + 18.0;
        // The marks were made at (0, 0): move them into place.
        let _ = writeln!(
            s,
            "<g transform=\"translate({x:.2},{y:.2})\">{mark}</g><text x=\"{:.2}\" y=\"{:.2}\">{}</text>",
            x + 18.0,
            y + 4.0,
            crate::svg::escape(text)
        );
    }
    s.push_str("</g>\n</svg>\n");
    Ok(s)
}

/// A time with at most six significant digits.
fn short_time(t: f64) -> String {
    if t != 0.0 && !(1e-4..1e6).contains(&t.abs()) {
        return format!("{t:.3e}");
    }
    let s = format!("{t:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s.is_empty() || s == "-" {
        "0".into()
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_round_trips_full_precision() {
        let nodes = vec![
            Vec3::new(0.1, 1.0 / 3.0, -2.0),
            Vec3::new(std::f64::consts::PI, -1e-300, 5.0),
            Vec3::new(1e20, 0.5, 0.0),
        ];
        let mut out = Vec::new();
        write_curve_csv(&nodes, 2, &mut out).unwrap();
        let text = String::from_utf8(out).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some("u,x,y"));
        for (j, line) in lines.enumerate() {
            let v: Vec<f64> = line.split(',').map(|s| s.parse().unwrap()).collect();
            assert_eq!(v, vec![j as f64 / 2.0, nodes[j].x, nodes[j].y]);
        }
        let frames = vec![
            CurveFrame {
                step: 0,
                time: 0.0,
                nodes: nodes.clone(),
            },
            CurveFrame {
                step: 7,
                time: 0.7,
                nodes,
            },
        ];
        let mut out = Vec::new();
        write_frames_csv(&frames, 3, &mut out).unwrap();
        let text = String::from_utf8(out).unwrap();
        assert_eq!(text.lines().count(), 7);
        assert!(text.starts_with("step,t,u,x,y,z\n0,0,0,0.1,"));
        assert!(text.lines().nth(4).unwrap().starts_with("7,0.7,0,0.1,"));
        assert!(write_curve_csv(&frames[0].nodes, 4, &mut Vec::new()).is_err());
    }

    #[test]
    fn picture_shows_every_curve_and_point() {
        let line = |s: f64| CurveFrame {
            step: s as usize,
            time: s,
            nodes: (0..=4)
                .map(|j| Vec3::new(j as f64, s * (j * (4 - j)) as f64, 0.0))
                .collect(),
        };
        let frames: Vec<CurveFrame> = (0..10).map(|k| line(k as f64)).collect();
        let picked = pick_frames(&frames, 3);
        let steps: Vec<usize> = picked.iter().map(|f| f.step).collect();
        assert_eq!(steps, vec![0, 2, 5, 7, 9]);
        let svg = svg_picture(&picked, &[Vec3::new(2.0, 30.0, 0.0)], &[], 2, 400, 300).unwrap();
        assert_eq!(svg.matches("<path class=\"frame-curve\"").count(), 5);
        // One data point, and its mark in the legend.
        assert_eq!(svg.matches("<circle").count(), 2);
        assert!(svg.contains("first: step 0, t = 0") && svg.contains("last: step 9, t = 9"));
        assert!(svg.contains(">3 intermediate<") && svg.contains(">data points<"));
        assert!(svg.contains("stroke-dasharray") && svg.contains("#b01818"));
        // Everything inside the picture (the legend's marks are drawn at the origin and moved
        // into place by a transform, so their own coordinates are not positions).
        let (body, _) = svg.split_once("<g class=\"legend\">").unwrap();
        for num in body
            .split(['"', ',', ' ', 'M', 'L'])
            .filter_map(|t| t.parse::<f64>().ok())
        {
            assert!((-10.0..=410.0).contains(&num), "{num}");
        }
        let bad = CurveFrame {
            step: 0,
            time: 0.0,
            nodes: vec![Vec3::new(f64::NAN, 0.0, 0.0); 3],
        };
        assert!(svg_picture(&[&bad], &[], &[], 2, 10, 10).is_err());
    }

    /// The `(coordinate, value)` of every tick label of one axis.
    fn ticks(svg: &str, class: &str, coord: &str) -> Vec<(f64, f64)> {
        svg.split(&format!("<text class=\"{class}\" "))
            .skip(1)
            .map(|t| {
                let at = t.find(&format!("{coord}=\"")).unwrap() + coord.len() + 2;
                let c: f64 = t[at..at + t[at..].find('"').unwrap()].parse().unwrap();
                let v: f64 = t[t.find('>').unwrap() + 1..t.find('<').unwrap()]
                    .parse()
                    .unwrap();
                (c, v)
            })
            .collect()
    }

    #[test]
    fn axes_ticks_sit_where_their_values_are_drawn() {
        // A parabola y = x² on [-1, 3] with its ends: x = 3 → y = 9 is drawn at the last point.
        let nodes: Vec<Vec3> = (0..=40)
            .map(|j| {
                let x = -1.0 + 0.1 * j as f64;
                Vec3::new(x, x * x, 0.0)
            })
            .collect();
        let f = CurveFrame {
            step: 3,
            time: 0.25,
            nodes,
        };
        let ends = [Vec3::new(-1.0, 1.0, 0.0), Vec3::new(3.0, 9.0, 0.0)];
        let svg = svg_picture(&[&f], &[], &ends, 2, 600, 800).unwrap();
        let xs = ticks(&svg, "tick-x", "x");
        let ys = ticks(&svg, "tick-y", "y");
        assert!(xs.len() >= 3 && ys.len() >= 3, "{xs:?} {ys:?}");
        // Pixel = a + b · value on each axis, with equal scales (b_y = −b_x).
        let fit = |t: &[(f64, f64)]| {
            let b = (t[t.len() - 1].0 - t[0].0) / (t[t.len() - 1].1 - t[0].1);
            (t[0].0 - b * t[0].1, b)
        };
        let (ax, bx) = fit(&xs);
        let (ay, by) = fit(&ys);
        for &(c, v) in &xs {
            assert!((c - (ax + bx * v)).abs() < 0.02, "{c} {v}");
        }
        // The y labels sit 4 px below their tick line (baseline offset).
        for &(c, v) in &ys {
            assert!((c - (ay + by * v)).abs() < 0.02, "{c} {v}");
        }
        assert!(bx > 0.0 && (by + bx).abs() < 1e-3 * bx, "{bx} {by}");
        // The curve's last point (3, 9) is drawn where the axes say.
        let d = svg.split("d=\"M").nth(1).unwrap();
        let d = &d[..d.find('"').unwrap()];
        let last = d.rsplit(" L").next().unwrap();
        let (px, py) = last.split_once(',').unwrap();
        let (px, py): (f64, f64) = (px.parse().unwrap(), py.parse().unwrap());
        assert!((px - (ax + bx * 3.0)).abs() < 0.05, "{px}");
        assert!((py + 4.0 - (ay + by * 9.0)).abs() < 0.05, "{py}");
        // Legend: the one frame and the end points.
        assert!(svg.contains(">curve: step 3, t = 0.25<"), "{svg}");
        assert!(svg.contains(">end points<") && !svg.contains(">data points<"));
    }
}
