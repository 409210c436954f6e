//! Plane geometry of point lists that every stage shares (no dependency on
//! any of them): the signed area of a closed polygon, by which a loop's
//! turning and its floor's area are known, and the point of a segment
//! nearest a point.

/// Twice the signed area of a closed polygon (positive counter-clockwise).
pub fn signed_area2(poly: &[[f64; 2]]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum()
}

/// The point of segment `a`–`b` nearest `p` (`a` for a segment of no
/// length).
pub fn closest_on_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    let ab = [b[0] - a[0], b[1] - a[1]];
    let l2 = ab[0] * ab[0] + ab[1] * ab[1];
    let t = if l2 > 0.0 {
        (((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1]) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    [a[0] + t * ab[0], a[1] + t * ab[1]]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_unit_square_has_area_one_and_turns_by_its_sign() {
        let sq = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        assert_eq!(signed_area2(&sq), 2.0);
        let mut cw = sq;
        cw.reverse();
        assert_eq!(signed_area2(&cw), -2.0);
    }

    #[test]
    fn the_nearest_point_of_a_segment_is_its_foot_or_an_end() {
        let (a, b) = ([0.0, 0.0], [10.0, 0.0]);
        assert_eq!(closest_on_segment([3.0, 4.0], a, b), [3.0, 0.0]);
        assert_eq!(closest_on_segment([-2.0, 1.0], a, b), a);
        assert_eq!(closest_on_segment([12.0, -1.0], a, b), b);
        assert_eq!(closest_on_segment([5.0, 5.0], a, a), a);
    }
}
