//! Plane geometry of point lists that every stage shares (no dependency on
//! any of them): the signed area of a closed polygon, by which a loop's
//! turning and its floor's area are known.

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
}
