//! Uniform hash grids for neighbour queries in linear time (docs/ALGORITHMS.md §4:
//! "do the detection with a spatial grid, not quadratic").

use rustc_hash::FxHashMap;

/// A 2D grid of items stored by the cells their bounding box touches.
#[derive(Debug)]
pub struct Grid2 {
    cell: f64,
    cells: FxHashMap<(i32, i32), Vec<u32>>,
}

impl Grid2 {
    /// An empty grid with square cells of side `cell` (mm).
    pub fn new(cell: f64) -> Self {
        Grid2 {
            cell,
            cells: FxHashMap::default(),
        }
    }

    fn key(&self, v: f64) -> i32 {
        (v / self.cell).floor().clamp(-1e9, 1e9) as i32
    }

    fn range(&self, a: [f64; 2], b: [f64; 2], pad: f64) -> (i32, i32, i32, i32) {
        (
            self.key(a[0].min(b[0]) - pad),
            self.key(a[0].max(b[0]) + pad),
            self.key(a[1].min(b[1]) - pad),
            self.key(a[1].max(b[1]) + pad),
        )
    }

    /// Stores `id` in every cell the segment's bounding box touches.
    pub fn insert_segment(&mut self, a: [f64; 2], b: [f64; 2], id: u32) {
        let (x0, x1, y0, y1) = self.range(a, b, 0.0);
        for x in x0..=x1 {
            for y in y0..=y1 {
                self.cells.entry((x, y)).or_default().push(id);
            }
        }
    }

    /// Calls `f` for every item in the cells within `pad` of the segment's
    /// bounding box (an item may be reported more than once).
    pub fn for_each_near_segment(
        &self,
        a: [f64; 2],
        b: [f64; 2],
        pad: f64,
        mut f: impl FnMut(u32),
    ) {
        let (x0, x1, y0, y1) = self.range(a, b, pad);
        for x in x0..=x1 {
            for y in y0..=y1 {
                if let Some(v) = self.cells.get(&(x, y)) {
                    v.iter().for_each(|&id| f(id));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_are_found_along_their_length() {
        let mut g = Grid2::new(1.0);
        g.insert_segment([0.0, 0.0], [10.0, 0.5], 7);
        let mut hit = false;
        g.for_each_near_segment([6.0, 0.2], [6.1, 0.3], 0.0, |i| hit |= i == 7);
        assert!(hit);
        let mut far = false;
        g.for_each_near_segment([6.0, 9.0], [6.1, 9.0], 0.5, |_| far = true);
        assert!(!far);
    }
}
