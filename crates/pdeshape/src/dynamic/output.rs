//! Outputs of a dynamic-curve run: the final curve and the frames of its evolution as CSV, and a
//! picture in the manner of the paper's Figs. 3–5 (initial, intermediate and final curve with the
//! data points) as SVG.

use crate::{Error, Result, Vec3};
use std::fmt::Write as _;
use std::io::Write;

/// The curve at one level of the run.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// The level `n`.
    pub step: usize,
    /// `t_n`.
    pub time: f64,
    /// `C(u_j, t_n)`, `u_j = j/J`.
    pub nodes: Vec<Vec3>,
}

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
    Error::io(e.to_string())
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
pub fn write_frames_csv(frames: &[Frame], dim: usize, w: &mut dyn Write) -> Result<()> {
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
pub fn write_frame_rows(f: &Frame, dim: usize, w: &mut dyn Write) -> Result<()> {
    check_dim(dim)?;
    let jn = (f.nodes.len().max(2) - 1) as f64;
    for (j, p) in f.nodes.iter().enumerate() {
        row(w, &[f.step as f64, f.time, j as f64 / jn], p, dim)?;
    }
    Ok(())
}

/// Picks the frames a picture shows: the first, the last and at most `intermediate` others,
/// evenly spread over the list.
pub fn pick_frames(frames: &[Frame], intermediate: usize) -> Vec<&Frame> {
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
/// (interior data points) as circles, `ends` (end points) as squares. Equal scales on both axes.
pub fn svg_picture(
    frames: &[&Frame],
    points: &[Vec3],
    ends: &[Vec3],
    dim: usize,
    width: u32,
    height: u32,
) -> Result<String> {
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
    let margin = 0.06 * w.min(h);
    let span = (x1 - x0).max(y1 - y0).max(f64::MIN_POSITIVE);
    let scale = ((w - 2.0 * margin) / (x1 - x0).max(span * 1e-9))
        .min((h - 2.0 * margin) / (y1 - y0).max(span * 1e-9));
    let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
    let map = |(x, y): (f64, f64)| (w / 2.0 + (x - cx) * scale, h / 2.0 - (y - cy) * scale);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\" \
         viewBox=\"0 0 {width} {height}\">"
    );
    let _ = writeln!(s, "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>");
    let last = frames.len() - 1;
    for (k, f) in frames.iter().enumerate() {
        let (stroke, extra) = if k == 0 && last > 0 {
            ("#888888", " stroke-dasharray=\"6 4\"")
        } else if k == last {
            ("#b01818", "")
        } else {
            ("#6fa8dc", "")
        };
        let jn = (f.nodes.len().max(2) - 1) as f64;
        let mut d = String::new();
        for (j, p) in f.nodes.iter().enumerate() {
            let (x, y) = map(plane(p, j as f64 / jn));
            let _ = write!(d, "{}{x:.2},{y:.2}", if j == 0 { "M" } else { " L" });
        }
        let _ = writeln!(
            s,
            "<path d=\"{d}\" fill=\"none\" stroke=\"{stroke}\" stroke-width=\"{}\"{extra}>\
             <title>step {}, t = {}</title></path>",
            if k == last { 2.0 } else { 1.2 },
            f.step,
            f.time
        );
    }
    for p in points {
        let (x, y) = map(plane(p, 0.0));
        let _ = writeln!(
            s,
            "<circle cx=\"{x:.2}\" cy=\"{y:.2}\" r=\"4\" fill=\"none\" stroke=\"black\" stroke-width=\"1.5\"/>"
        );
    }
    for p in ends {
        let (x, y) = map(plane(p, 0.0));
        let _ = writeln!(
            s,
            "<rect x=\"{:.2}\" y=\"{:.2}\" width=\"7\" height=\"7\" fill=\"black\"/>",
            x - 3.5,
            y - 3.5
        );
    }
    s.push_str("</svg>\n");
    Ok(s)
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
            Frame {
                step: 0,
                time: 0.0,
                nodes: nodes.clone(),
            },
            Frame {
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
        let line = |s: f64| Frame {
            step: s as usize,
            time: s,
            nodes: (0..=4)
                .map(|j| Vec3::new(j as f64, s * (j * (4 - j)) as f64, 0.0))
                .collect(),
        };
        let frames: Vec<Frame> = (0..10).map(|k| line(k as f64)).collect();
        let picked = pick_frames(&frames, 3);
        let steps: Vec<usize> = picked.iter().map(|f| f.step).collect();
        assert_eq!(steps, vec![0, 2, 5, 7, 9]);
        let svg = svg_picture(&picked, &[Vec3::new(2.0, 30.0, 0.0)], &[], 2, 400, 300).unwrap();
        assert_eq!(svg.matches("<path").count(), 5);
        assert_eq!(svg.matches("<circle").count(), 1);
        assert!(svg.contains("stroke-dasharray") && svg.contains("#b01818"));
        // Everything inside the picture.
        for num in svg
            .split(['"', ',', ' ', 'M', 'L'])
            .filter_map(|t| t.parse::<f64>().ok())
        {
            assert!((-10.0..=410.0).contains(&num), "{num}");
        }
        let bad = Frame {
            step: 0,
            time: 0.0,
            nodes: vec![Vec3::new(f64::NAN, 0.0, 0.0); 3],
        };
        assert!(svg_picture(&[&bad], &[], &[], 2, 10, 10).is_err());
    }
}
