//! The mesh's sections read along rays (docs/MESHES.md, "Fitting"): the
//! foot's wall as Ψ and its centre, the loops of a section about it, and
//! where each ray from Ψ meets a section's wall, D(k, j).

use super::*;
/// The foot's wall (the lowest section's) as Ψ: its area centroid, o,
/// and [`RAYS`] points evenly along it, about o.
pub(super) fn foot_frame(cut: &[sections::Section]) -> ([f64; 2], Vec<[f64; 2]>) {
    let foot = wall_loop(&cut[0].loops);
    let c = centroid(foot);
    let psi = resample(foot, RAYS)
        .into_iter()
        .map(|p| [p[0] - c[0], p[1] - c[1]])
        .collect();
    (c, psi)
}

/// A section's loops about the centre `c`, resampled a point every
/// 0.4 mm (16 to 4,000 a loop): the rays' cost does not grow with the
/// mesh's triangles.
pub(super) fn about(sec: &sections::Section, c: [f64; 2]) -> Vec<Vec<[f64; 2]>> {
    sec.loops
        .iter()
        .map(|l| {
            let k = (perimeter(l) / 0.4).ceil().clamp(16.0, 4000.0) as usize;
            resample(l, k)
                .into_iter()
                .map(|p| [p[0] - c[0], p[1] - c[1]])
                .collect()
        })
        .collect()
}

/// Whether loop `a` lies inside loop `b` (its first point does).
pub(super) fn nested(a: &[[f64; 2]], b: &[[f64; 2]]) -> bool {
    let p = a[0];
    let mut inside = false;
    for i in 0..b.len() {
        let (q, r) = (b[i], b[(i + 1) % b.len()]);
        if (q[1] > p[1]) != (r[1] > p[1])
            && p[0] < q[0] + (p[1] - q[1]) / (r[1] - q[1]) * (r[0] - q[0])
        {
            inside = !inside;
        }
    }
    inside
}

/// Whether loop `l` is a wall round the section's middle: no other loop
/// of the section holds it (a shell's inner loop is inside the outer).
pub(super) fn around(l: &[[f64; 2]], all: &[Vec<[f64; 2]>]) -> bool {
    all.iter()
        .all(|o| std::ptr::eq(o.as_slice(), l) || !nested(l, o))
}

/// Which of a section's loops is its outside: the largest by area.
pub(super) fn outside(loops: &[Vec<[f64; 2]>]) -> Option<usize> {
    (0..loops.len()).max_by(|&a, &b| {
        signed_area2(&loops[a])
            .abs()
            .total_cmp(&signed_area2(&loops[b]).abs())
    })
}

/// The loop that stands for a section's wall in plan: the outer of two.
pub(super) fn wall_loop(loops: &[Vec<[f64; 2]>]) -> &[[f64; 2]] {
    &loops[outside(loops).expect("a section has a loop")]
}

/// The area centroid of a loop.
pub(super) fn centroid(l: &[[f64; 2]]) -> [f64; 2] {
    let (mut a, mut cx, mut cy) = (0.0, 0.0, 0.0);
    for i in 0..l.len() {
        let (p, q) = (l[i], l[(i + 1) % l.len()]);
        let w = p[0] * q[1] - q[0] * p[1];
        a += w;
        cx += (p[0] + q[0]) * w;
        cy += (p[1] + q[1]) * w;
    }
    [cx / (3.0 * a), cy / (3.0 * a)]
}

pub(super) fn perimeter(l: &[[f64; 2]]) -> f64 {
    (0..l.len())
        .map(|i| {
            let (p, q) = (l[i], l[(i + 1) % l.len()]);
            (q[0] - p[0]).hypot(q[1] - p[1])
        })
        .sum()
}

/// The angle the path `a` → `b` → `c` turns by at `b` (radians, to the
/// left positive).
pub(super) fn bend(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    let (e, f) = ([b[0] - a[0], b[1] - a[1]], [c[0] - b[0], c[1] - b[1]]);
    (e[0] * f[1] - e[1] * f[0]).atan2(e[0] * f[0] + e[1] * f[1])
}

/// `p` turned about o by the angle whose sine and cosine are `(s, c)`.
pub(super) fn turn_by(p: [f64; 2], (s, c): (f64, f64)) -> [f64; 2] {
    [c * p[0] - s * p[1], s * p[0] + c * p[1]]
}

/// Where each point of the closed polyline Ψ lies along it: its arc
/// length from the first point as a fraction of the whole loop, as the
/// design places its columns; and the loop's length (mm).
pub(super) fn places(psi: &[[f64; 2]]) -> (Vec<f64>, f64) {
    let mut u = crate::curves::arc_lengths(psi);
    let total = perimeter(psi);
    for x in &mut u {
        *x /= total;
    }
    (u, total)
}

/// A loop's vertex that turns by more than this is a corner (radians):
/// a 20° bend.
const CORNER: f64 = 0.35;

/// `k` points evenly spaced along a closed loop, counter-clockwise, each
/// corner of the loop (a bend over 20°) kept in place of the point
/// nearest it: a point between two even ones would cut a square's corner
/// by up to a third of their spacing, where no ray measures.
pub(super) fn resample(l: &[[f64; 2]], k: usize) -> Vec<[f64; 2]> {
    let mut l = l.to_vec();
    if signed_area2(&l) < 0.0 {
        l.reverse();
    }
    let total = perimeter(&l);
    let mut out = Vec::with_capacity(k);
    let (mut i, mut walked) = (0usize, 0.0);
    for m in 0..k {
        let want = total * m as f64 / k as f64;
        loop {
            let (p, q) = (l[i % l.len()], l[(i + 1) % l.len()]);
            let seg = (q[0] - p[0]).hypot(q[1] - p[1]);
            if walked + seg >= want || i >= 2 * l.len() {
                let t = if seg > 0.0 {
                    (want - walked) / seg
                } else {
                    0.0
                };
                out.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
                break;
            }
            walked += seg;
            i += 1;
        }
    }
    // Corners: each takes the place of the even point nearest it along
    // the loop (within half a spacing, so the order stays).
    let n = l.len();
    let mut at = 0.0;
    for v in 0..n {
        let (a, p, b) = (l[(v + n - 1) % n], l[v], l[(v + 1) % n]);
        if bend(a, p, b).abs() > CORNER && total > 0.0 {
            let m = (at / total * k as f64).round() as usize % k;
            out[m] = p;
        }
        at += (b[0] - p[0]).hypot(b[1] - p[1]);
    }
    out
}

/// Where the ray `o + t·d` crosses the loop: every t.
pub(super) fn hits(l: &[[f64; 2]], o: [f64; 2], d: [f64; 2]) -> Vec<f64> {
    crossings(l, o, d).into_iter().map(|(t, _)| t).collect()
}

/// Where the ray `o + t·d` crosses the loop: every t, rising, and the
/// segment it crosses (from point i to i + 1).
pub(super) fn crossings(l: &[[f64; 2]], o: [f64; 2], d: [f64; 2]) -> Vec<(f64, usize)> {
    let mut ts = Vec::new();
    for i in 0..l.len() {
        let (p, q) = (l[i], l[(i + 1) % l.len()]);
        let e = [q[0] - p[0], q[1] - p[1]];
        let den = d[0] * e[1] - d[1] * e[0];
        if den.abs() < 1e-12 {
            continue;
        }
        let w = [p[0] - o[0], p[1] - o[1]];
        let t = (w[0] * e[1] - w[1] * e[0]) / den;
        let s = (w[0] * d[1] - w[1] * d[0]) / den;
        if (-1e-9..1.0 + 1e-9).contains(&s) {
            ts.push((t, i));
        }
    }
    // A ray through a vertex crosses both its edges at one place.
    ts.sort_by(|a, b| a.0.total_cmp(&b.0));
    ts.dedup_by(|a, b| (a.0 - b.0).abs() < 1e-6);
    ts
}

/// D(k, j) by section and ray, each ray's direction, and the folds taken
/// in: how many rays, and where the largest fold was (x, y, z).
type Offsets = (Vec<Vec<f64>>, Vec<[f64; 2]>, (usize, Option<[f64; 3]>));

/// The direction Ψ's point `j` is offset along (a unit vector): from the
/// centre o (radial), or Ψ's outward normal there (right of travel on
/// this counter-clockwise Ψ), as a loop's normal offsets move.
pub(super) fn ray(psi: &[[f64; 2]], j: usize, offset: Offset) -> [f64; 2] {
    let n = psi.len();
    match offset {
        Offset::Radial => {
            let p = psi[j];
            let r = p[0].hypot(p[1]).max(1e-9);
            [p[0] / r, p[1] / r]
        }
        Offset::Normal => {
            let (a, b) = (psi[(j + n - 1) % n], psi[(j + 1) % n]);
            let t = [b[0] - a[0], b[1] - a[1]];
            let l = t[0].hypot(t[1]).max(1e-12);
            [t[1] / l, -t[0] / l]
        }
    }
}

/// D(k, j): for each section k and each point j of Ψ, the offset of the
/// section's wall along the ray of the frame (`offset`), and each ray's
/// direction. Where a ray from the centre (radial) meets a loop more than
/// once, the wall folds back across it: a fold no wider than `fold_mm`
/// along the wall (a crease a bead cannot follow) is read at its
/// outermost crossing, the outside; a wider one is refused.
pub(super) fn offsets(
    psi: &[[f64; 2]],
    zs: &[f64],
    loops: &[Vec<Vec<[f64; 2]>>],
    offset: Offset,
    fold_mm: f64,
) -> std::result::Result<Offsets, String> {
    let n = psi.len();
    let rays: Vec<([f64; 2], [f64; 2], f64)> = (0..n)
        .map(|j| {
            let (p, dir) = (psi[j], ray(psi, j, offset));
            match offset {
                Offset::Radial => ([0.0, 0.0], dir, p[0].hypot(p[1])),
                Offset::Normal => (p, dir, 0.0),
            }
        })
        .collect();
    let mut d = Vec::with_capacity(loops.len());
    let mut folds = (0usize, None::<(f64, [f64; 3])>);
    for (k, sec) in loops.iter().enumerate() {
        // One loop a section: the bead's centre line (docs/MESHES.md,
        // "The outside is the pot").
        let Some(l) = sec.first() else {
            return Err(format!("it has nothing at z = {:.1} mm", zs[k]));
        };
        let mut row = Vec::with_capacity(n);
        match offset {
            Offset::Radial => {
                let ahead: Vec<Vec<f64>> = rays
                    .iter()
                    .map(|&(o, dir, _)| hits(l, o, dir).into_iter().filter(|&t| t > 0.0).collect())
                    .collect();
                let refuse = |j: usize| {
                    let (_, dir, base) = rays[j];
                    format!(
                        "its wall at z = {:.1} mm does not go once round its foot's centre (a ray from the centre meets it {} times, near ({:.1}, {:.1}) mm)",
                        zs[k],
                        ahead[j].len(),
                        dir[0] * base,
                        dir[1] * base
                    )
                };
                // Each run of rays that meet the wall more than once: a
                // fold as wide as the run and a ray's spacing either side.
                let bad: Vec<bool> = ahead.iter().map(|a| a.len() != 1).collect();
                if bad.iter().all(|&b| b) {
                    return Err(refuse(0));
                }
                let start = (0..n).find(|&j| !bad[j]).unwrap_or(0);
                let mut j = 0;
                while j < n {
                    let a = (start + j) % n;
                    if !bad[a] {
                        j += 1;
                        continue;
                    }
                    let mut len = 0;
                    while len < n && bad[(a + len) % n] {
                        len += 1;
                    }
                    let run: Vec<usize> = (0..len).map(|i| (a + i) % n).collect();
                    if run.iter().any(|&i| ahead[i].is_empty()) {
                        return Err(refuse(run[0]));
                    }
                    let r = run
                        .iter()
                        .map(|&i| ahead[i].iter().cloned().fold(0.0, f64::max))
                        .fold(0.0, f64::max);
                    let wide = (len + 1) as f64 * std::f64::consts::TAU * r / n as f64;
                    if wide > fold_mm {
                        return Err(refuse(run[0]));
                    }
                    folds.0 += len;
                    if folds.1.is_none_or(|(w, _)| wide > w) {
                        let (_, dir, _) = rays[run[0]];
                        folds.1 = Some((wide, [dir[0] * r, dir[1] * r, zs[k]]));
                    }
                    j += len;
                }
                for (j, a) in ahead.iter().enumerate() {
                    let t = a.iter().cloned().fold(f64::MIN, f64::max);
                    row.push(t - rays[j].2);
                }
            }
            Offset::Normal => {
                for &(o, dir, base) in &rays {
                    let t = match hits(l, o, dir).into_iter().min_by(|a, b| a.abs().total_cmp(&b.abs())) {
                        Some(t) => t,
                        None => {
                            return Err(format!(
                                "its wall at z = {:.1} mm is not across the foot's wall near ({:.1}, {:.1}) mm (it leans out beyond where the foot reaches)",
                                zs[k], o[0], o[1]
                            ))
                        }
                    };
                    row.push(t - base);
                }
            }
        }
        d.push(row);
    }
    Ok((
        d,
        rays.iter().map(|r| r.1).collect(),
        (folds.0, folds.1.map(|f| f.1)),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A circle of radius 40 whose wall folds back across the rays
    /// between `from` and `to` degrees: out at 40, back at 38, on again.
    fn folded(from: f64, to: f64) -> Vec<[f64; 2]> {
        let at = |deg: f64, r: f64| {
            let (s, c) = deg.to_radians().sin_cos();
            [r * c, r * s]
        };
        let mut l = vec![
            at(from - 0.5, 40.0),
            at(to, 40.0),
            at(from, 38.0),
            at(to + 0.5, 38.0),
        ];
        let mut deg = (to + 1.5).ceil();
        while deg < from - 1.0 + 360.0 {
            l.push(at(deg, 40.0));
            deg += 1.0;
        }
        l
    }

    fn rays_of_a_circle() -> Vec<[f64; 2]> {
        (0..RAYS)
            .map(|j| {
                let (s, c) = (j as f64 * std::f64::consts::TAU / RAYS as f64).sin_cos();
                [40.0 * c, 40.0 * s]
            })
            .collect()
    }

    #[test]
    fn a_fold_narrower_than_the_limit_is_read_at_its_outside_and_a_wide_one_refused() {
        let psi = rays_of_a_circle();
        // A fold across the ray at 0°, under a degree wide (0.7 mm).
        let narrow = vec![vec![folded(-0.4, 0.4)]];
        let (d, _, folds) = offsets(&psi, &[10.0], &narrow, Offset::Radial, 6.0).unwrap();
        assert_eq!(folds.0, 1, "one ray across the fold");
        let at = folds.1.unwrap();
        assert!(
            (at[0] - 40.0).abs() < 0.1 && at[1].abs() < 0.1 && at[2] == 10.0,
            "{at:?}"
        );
        // Read at the outside: no offset from Ψ's radius.
        assert!(d[0][0].abs() < 0.01, "{}", d[0][0]);
        // Twenty degrees (14 mm along the wall): a real overhang in plan.
        let wide = vec![vec![folded(-10.0, 10.0)]];
        let e = offsets(&psi, &[10.0], &wide, Offset::Radial, 6.0).unwrap_err();
        assert!(
            e.contains("does not go once round its foot's centre"),
            "{e}"
        );
    }
}
