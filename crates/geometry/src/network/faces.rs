//! The faces of a network: loops traced through the counterclockwise order of the pieces at
//! every node.

use super::normals::{leaving, leaving_by_node};
use super::{Face, Network, Run};
use crate::{Result, TAU};
use std::f64::consts::PI;

/// A joint of two pieces of one curve turns by less than this (radians, 0.5°) to be inside a
/// side rather than a corner.
const STRAIGHT: f64 = 0.5 * PI / 180.0;

/// The faces to fill and the loops left open.
pub(super) fn trace(net: &Network) -> Result<(Vec<Face>, Vec<Face>)> {
    let out = leaving_by_node(net, net.nodes.len());
    let halves = 2 * net.edges.len();
    // The angle of every half-edge about its node's normal, and its place in the node's
    // counterclockwise order.
    let mut angle = vec![0.0; halves];
    let mut place = vec![0usize; halves];
    let mut order: Vec<Vec<usize>> = Vec::with_capacity(out.len());
    for (k, hs) in out.iter().enumerate() {
        let n = net.nodes[k].normal;
        let project = |h: usize| {
            let t = leaving(net, h);
            t - n * n.dot(&t)
        };
        let e1 = hs
            .iter()
            .map(|&h| project(h))
            .find(|p| p.norm() > 1e-12)
            .map_or_else(|| any_normal(n), |p| p.normalize());
        let e2 = n.cross(&e1);
        for &h in hs {
            let p = project(h);
            angle[h] = p.dot(&e2).atan2(p.dot(&e1)).rem_euclid(TAU);
        }
        let mut sorted = hs.clone();
        sorted.sort_by(|&a, &b| angle[a].total_cmp(&angle[b]).then(a.cmp(&b)));
        for (i, &h) in sorted.iter().enumerate() {
            place[h] = i;
        }
        order.push(sorted);
    }
    let dest = |h: usize| {
        let e = &net.edges[h / 2];
        if h.is_multiple_of(2) {
            e.end
        } else {
            e.start
        }
    };
    // Leave each node on the half-edge just clockwise of the one arrived on (face on the left).
    let next = |h: usize| {
        let v = dest(h);
        let twin = h ^ 1;
        let list = &order[v];
        list[(place[twin] + list.len() - 1) % list.len()]
    };
    let corner = |h: usize, g: usize| {
        // The face's angle at dest(h), from the leaving half-edge g counterclockwise to the
        // piece arrived on.
        let a = (angle[h ^ 1] - angle[g]).rem_euclid(TAU);
        if g == h ^ 1 || a == 0.0 {
            TAU
        } else {
            a
        }
    };
    let mut seen = vec![false; halves];
    let mut faces = Vec::new();
    let mut open = Vec::new();
    for first in 0..halves {
        if seen[first] {
            continue;
        }
        let mut cycle = Vec::new();
        let mut h = first;
        while !seen[h] {
            seen[h] = true;
            let g = next(h);
            cycle.push((h, corner(h, g)));
            h = g;
        }
        let face = group(net, &cycle);
        let n = face.sides.len() as f64;
        if face.angle_sum < n * PI {
            faces.push(face);
        } else {
            open.push(face);
        }
    }
    Ok((faces, open))
}

/// A traced cycle (half-edges with the face's angle at each one's end) as a face: adjacent
/// pieces of one curve that meet straight are one side.
fn group(net: &Network, cycle: &[(usize, f64)]) -> Face {
    let m = cycle.len();
    let run = |h: usize| Run {
        edge: h / 2,
        forward: h.is_multiple_of(2),
    };
    // Whether the cycle passes straight from piece k to piece k + 1 along one curve.
    let straight = |k: usize| {
        let (h, a) = cycle[k];
        let g = cycle[(k + 1) % m].0;
        let (e, f) = (&net.edges[h / 2], &net.edges[g / 2]);
        let contiguous = e.curve == f.curve
            && h % 2 == g % 2
            && if h.is_multiple_of(2) {
                e.t1 == f.t0
            } else {
                e.t0 == f.t1
            };
        contiguous && (a - PI).abs() < STRAIGHT && m > 1
    };
    // Start at a real corner, so that no side wraps around the start.
    let start = (0..m).find(|&k| !straight((k + m - 1) % m)).unwrap_or(0);
    let mut sides: Vec<Vec<Run>> = Vec::new();
    let mut angle_sum = 0.0;
    let mut current = Vec::new();
    for i in 0..m {
        let k = (start + i) % m;
        current.push(run(cycle[k].0));
        if !straight(k) {
            angle_sum += cycle[k].1;
            sides.push(std::mem::take(&mut current));
        }
    }
    if !current.is_empty() {
        sides.push(current);
    }
    Face { sides, angle_sum }
}

fn any_normal(n: crate::Vec3) -> crate::Vec3 {
    let a = if n.x.abs() < 0.9 {
        crate::Vec3::x()
    } else {
        crate::Vec3::y()
    };
    n.cross(&a).normalize()
}
