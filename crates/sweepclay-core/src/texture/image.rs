//! A picture as a texture's relief (docs/FORMATS.md, "texture"): a PNG
//! decoded to grey within the pixel caps, read bilinearly.

use super::*;

/// A greyscale image, rows from the top, values in [0, 1].
#[derive(Clone, Debug, PartialEq)]
pub struct Grey {
    /// Pixels across.
    pub width: usize,
    /// Pixels down.
    pub height: usize,
    /// Row-major grey values.
    pub v: Vec<f32>,
}

impl Grey {
    /// Decodes a PNG (any colour type and depth; colour is averaged to
    /// grey, transparency counts as white), refusing files over
    /// [`MAX_IMAGE_BYTES`] and images over [`MAX_IMAGE_PIXELS`] before
    /// allocating for their pixels.
    pub fn from_png(bytes: &[u8], key: &str) -> Result<Grey> {
        let mut budget = MAX_IMAGE_PIXELS;
        Grey::from_png_within(bytes, key, &mut budget)
    }

    /// [`Grey::from_png`], counting the image's pixels against `budget`
    /// (what is left of the design's [`MAX_DESIGN_PIXELS`]) before any is
    /// decoded, and refusing it by name where they do not fit.
    pub fn from_png_within(bytes: &[u8], key: &str, budget: &mut usize) -> Result<Grey> {
        if bytes.len() > MAX_IMAGE_BYTES {
            return Err(Error::invalid(
                key,
                format!(
                    "the image is {} bytes, over the cap of {MAX_IMAGE_BYTES}",
                    bytes.len()
                ),
            ));
        }
        let bad = |e: &dyn std::fmt::Display| Error::invalid(key, format!("not a PNG: {e}"));
        let mut dec = png::Decoder::new(std::io::Cursor::new(bytes));
        dec.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
        let header = dec.read_header_info().map_err(|e| bad(&e))?;
        let (w, h) = (header.width as usize, header.height as usize);
        if w == 0 || h == 0 || w.saturating_mul(h) > MAX_IMAGE_PIXELS {
            return Err(Error::invalid(
                key,
                format!(
                    "the image is {w} × {h} pixels; at most {MAX_IMAGE_PIXELS} pixels, at least 1"
                ),
            ));
        }
        if w * h > *budget {
            return Err(Error::invalid(
                key,
                format!(
                    "the image is {w} × {h} pixels, and the design's pictures may come to {MAX_DESIGN_PIXELS} pixels in all ({} left); use smaller pictures (a texture keeps at most a few hundred pixels across)",
                    *budget
                ),
            ));
        }
        *budget -= w * h;
        let mut reader = dec.read_info().map_err(|e| bad(&e))?;
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).map_err(|e| bad(&e))?;
        let chans = info.color_type.samples();
        let line = info.line_size;
        let mut v = Vec::with_capacity(w * h);
        for y in 0..h {
            let row = &buf[y * line..y * line + w * chans];
            for px in row.chunks_exact(chans) {
                let f = |b: u8| f32::from(b) / 255.0;
                let (grey, alpha) = match chans {
                    1 => (f(px[0]), 1.0),
                    2 => (f(px[0]), f(px[1])),
                    3 => ((f(px[0]) + f(px[1]) + f(px[2])) / 3.0, 1.0),
                    _ => ((f(px[0]) + f(px[1]) + f(px[2])) / 3.0, f(px[3])),
                };
                v.push(grey * alpha + (1.0 - alpha));
            }
        }
        Ok(Grey {
            width: w,
            height: h,
            v,
        })
    }

    /// The image averaged down to at most `w` × `h` cells (box filter),
    /// so the sampling resolves what is left of it.
    pub(super) fn fit(&self, w: usize, h: usize) -> Grey {
        let (w, h) = (w.clamp(1, self.width), h.clamp(1, self.height));
        if w == self.width && h == self.height {
            return self.clone();
        }
        let mut sum = vec![0.0f32; w * h];
        let mut n = vec![0u32; w * h];
        for y in 0..self.height {
            let cy = y * h / self.height;
            for x in 0..self.width {
                let c = cy * w + x * w / self.width;
                sum[c] += self.v[y * self.width + x];
                n[c] += 1;
            }
        }
        Grey {
            width: w,
            height: h,
            v: sum
                .iter()
                .zip(&n)
                .map(|(s, &k)| s / k.max(1) as f32)
                .collect(),
        }
    }

    /// Bilinear grey at (x, y) ∈ [0, 1]² (y from the top), clamped at the
    /// edges; across x, wrapped when `wrap` (round a loop).
    pub(super) fn at(&self, x: f64, y: f64, wrap: bool) -> f64 {
        let fx = if wrap {
            x.rem_euclid(1.0) * self.width as f64 - 0.5
        } else {
            (x * self.width as f64 - 0.5).clamp(0.0, (self.width - 1) as f64)
        };
        let fy = (y * self.height as f64 - 0.5).clamp(0.0, (self.height - 1) as f64);
        let (x0, y0) = (fx.floor(), fy.floor());
        let (tx, ty) = (fx - x0, fy - y0);
        let col = |k: f64| -> usize {
            let k = k as i64;
            if wrap {
                k.rem_euclid(self.width as i64) as usize
            } else {
                k.clamp(0, self.width as i64 - 1) as usize
            }
        };
        let (xa, xb) = (col(x0), col(x0 + 1.0));
        let (ya, yb) = (y0 as usize, (y0 as usize + 1).min(self.height - 1));
        let g = |x: usize, y: usize| f64::from(self.v[y * self.width + x]);
        (g(xa, ya) * (1.0 - tx) + g(xb, ya) * tx) * (1.0 - ty)
            + (g(xa, yb) * (1.0 - tx) + g(xb, yb) * tx) * ty
    }
}
