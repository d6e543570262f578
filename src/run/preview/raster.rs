//! A small software rasterizer: shaded triangles and lines with a depth buffer, and 8×8
//! bitmap text. Written here because what the preview needs is this small (a dozen lines per
//! primitive) and the rendering crates that would do it bring a GPU stack.

use glam::{DVec2, DVec3};

/// An RGB colour, components 0..=1.
pub type Colour = [f32; 3];

/// A picture being drawn: colour and depth per pixel. Points are in pixels (x right, y down)
/// with a depth (larger is farther).
pub struct Canvas {
    pub width: usize,
    pub height: usize,
    colour: Vec<Colour>,
    depth: Vec<f64>,
}

impl Canvas {
    /// An empty canvas of `width` × `height` pixels filled with `background`.
    pub fn new(width: usize, height: usize, background: Colour) -> Canvas {
        Canvas {
            width,
            height,
            colour: vec![background; width * height],
            depth: vec![f64::INFINITY; width * height],
        }
    }

    /// Writes `colour` at pixel (x, y) if `depth` is nearer than what is there.
    fn plot(&mut self, x: usize, y: usize, depth: f64, colour: Colour) {
        let k = y * self.width + x;
        if depth < self.depth[k] {
            self.depth[k] = depth;
            self.colour[k] = colour;
        }
    }

    /// Fills the triangle with corners `p` (pixel x, y and depth), its colour interpolated
    /// from the corners' `colours` (Gouraud shading). Pixels whose centre lies inside (or on
    /// an edge) are drawn.
    pub fn triangle(&mut self, p: [DVec3; 3], colours: [Colour; 3]) {
        let area = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[2].x - p[0].x) * (p[1].y - p[0].y);
        if area.abs() < 1e-12 {
            return;
        }
        let lo = p[0].min(p[1]).min(p[2]);
        let hi = p[0].max(p[1]).max(p[2]);
        let (x0, y0) = (lo.x.round().max(0.0) as usize, lo.y.round().max(0.0) as usize);
        let x1 = (hi.x.round().max(0.0) as usize).min(self.width);
        let y1 = (hi.y.round().max(0.0) as usize).min(self.height);
        if x0 >= x1 || y0 >= y1 {
            return;
        }
        // Barycentric weight of corner i: a linear function of the pixel centre, the edge
        // function of the opposite edge over the area; stepped along each row.
        let weight = |i: usize| {
            let (a, b) = (p[(i + 1) % 3], p[(i + 2) % 3]);
            let (dx, dy) = ((a.y - b.y) / area, (b.x - a.x) / area);
            (dx, dy, -(dx * a.x + dy * a.y))
        };
        let w = [weight(0), weight(1), weight(2)];
        let (fx, fy) = (x0 as f64 + 0.5, y0 as f64 + 0.5);
        for y in y0..y1 {
            let py = fy + (y - y0) as f64;
            let mut b = w.map(|(dx, dy, c)| dx * fx + dy * py + c);
            for x in x0..x1 {
                if b[0] >= 0.0 && b[1] >= 0.0 && b[2] >= 0.0 {
                    let depth = b[0] * p[0].z + b[1] * p[1].z + b[2] * p[2].z;
                    let k = y * self.width + x;
                    if depth < self.depth[k] {
                        self.depth[k] = depth;
                        let (b0, b1, b2) = (b[0] as f32, b[1] as f32, b[2] as f32);
                        self.colour[k] = [0, 1, 2]
                            .map(|i| b0 * colours[0][i] + b1 * colours[1][i] + b2 * colours[2][i]);
                    }
                }
                for i in 0..3 {
                    b[i] += w[i].0;
                }
            }
        }
    }

    /// Draws a line `width` pixels wide from `a` to `b` (pixel x, y and depth), hidden where
    /// the surface is nearer.
    pub fn line(&mut self, a: DVec3, b: DVec3, width: f64, colour: Colour) {
        let steps = a.truncate().distance(b.truncate()).ceil().max(1.0) as usize;
        let r = 0.5 * width;
        for s in 0..=steps {
            let p = a.lerp(b, s as f64 / steps as f64);
            let (xs, ys) =
                ((p.x - r).floor().max(0.0) as usize, (p.y - r).floor().max(0.0) as usize);
            for y in ys..((p.y + r).ceil() as usize).min(self.height) {
                for x in xs..((p.x + r).ceil() as usize).min(self.width) {
                    let c = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
                    if c.distance(p.truncate()) <= r {
                        self.plot(x, y, p.z, colour);
                    }
                }
            }
        }
    }

    /// The canvas shrunk by `factor` in each direction, each pixel the mean of a
    /// `factor` × `factor` block (anti-aliasing by supersampling): 8-bit RGB, row by row.
    pub fn downsample(&self, factor: usize) -> (usize, usize, Vec<u8>) {
        let (w, h) = (self.width / factor, self.height / factor);
        let mut out = Vec::with_capacity(w * h * 3);
        let n = (factor * factor) as f32;
        for y in 0..h {
            for x in 0..w {
                let mut sum = [0.0f32; 3];
                for dy in 0..factor {
                    for dx in 0..factor {
                        let c = self.colour[(y * factor + dy) * self.width + x * factor + dx];
                        (0..3).for_each(|i| sum[i] += c[i]);
                    }
                }
                out.extend(sum.map(|s| (s / n * 255.0).round().clamp(0.0, 255.0) as u8));
            }
        }
        (w, h, out)
    }
}

/// Width of one character of [`text`] at scale 1 (pixels): font8x8's glyphs are 8 x 8.
pub const GLYPH_PX: usize = 8;

/// Writes `text` into the 8-bit RGB image `rgb` (`width` pixels wide) with its top-left
/// corner at (x, y), each font pixel `scale` pixels wide, in the 8×8 font of the `font8x8`
/// crate (Basic Latin; other characters are left blank).
pub fn text(
    rgb: &mut [u8],
    width: usize,
    (x, y): (usize, usize),
    text: &str,
    scale: usize,
    colour: [u8; 3],
) {
    for (k, ch) in text.chars().enumerate() {
        let glyph = font8x8::legacy::BASIC_LEGACY.get(ch as usize).copied().unwrap_or([0; 8]);
        for (row, bits) in glyph.iter().enumerate() {
            for col in (0..GLYPH_PX).filter(|col| bits >> col & 1 == 1) {
                let at = (x + (k * GLYPH_PX + col) * scale, y + row * scale);
                fill(rgb, width, at, (scale, scale), colour);
            }
        }
    }
}

/// Fills a `size` (width, height) rectangle with its top-left corner at (x, y) in the 8-bit
/// RGB image `rgb` (`width` pixels wide).
pub fn fill(
    rgb: &mut [u8],
    width: usize,
    (x, y): (usize, usize),
    size: (usize, usize),
    colour: [u8; 3],
) {
    let height = rgb.len() / 3 / width;
    for py in y..(y + size.1).min(height) {
        for px in x..(x + size.0).min(width) {
            rgb[3 * (py * width + px)..3 * (py * width + px) + 3].copy_from_slice(&colour);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_nearer_triangle_wins_and_colours_interpolate() {
        let mut c = Canvas::new(20, 20, [1.0; 3]);
        let far =
            [DVec3::new(0.0, 0.0, 5.0), DVec3::new(20.0, 0.0, 5.0), DVec3::new(0.0, 20.0, 5.0)];
        let near = far.map(|p| DVec3::new(p.x, p.y, 1.0));
        c.triangle(near, [[0.0, 0.0, 0.0]; 3]);
        c.triangle(far, [[1.0, 0.0, 0.0]; 3]);
        let (_, _, rgb) = c.downsample(1);
        assert_eq!(&rgb[0..3], &[0, 0, 0], "the near black triangle stays in front");
        // Beyond the diagonal nothing was drawn: the background.
        let k = 3 * (19 * 20 + 19);
        assert_eq!(&rgb[k..k + 3], &[255, 255, 255]);

        let mut c = Canvas::new(10, 1, [0.0; 3]);
        let strip =
            [DVec3::new(0.0, -1.0, 0.0), DVec3::new(10.0, -1.0, 0.0), DVec3::new(0.0, 3.0, 0.0)];
        c.triangle(strip, [[0.0; 3], [1.0; 3], [0.0; 3]]);
        let (_, _, rgb) = c.downsample(1);
        assert!(rgb[0] < rgb[3 * 3], "brighter towards the white corner: {rgb:?}");
    }

    #[test]
    fn lines_hide_behind_the_surface_and_downsampling_averages() {
        let mut c = Canvas::new(4, 4, [0.0; 3]);
        let wall =
            [DVec3::new(0.0, 0.0, 1.0), DVec3::new(8.0, 0.0, 1.0), DVec3::new(0.0, 8.0, 1.0)];
        c.triangle(wall, [[0.0, 0.0, 1.0]; 3]);
        c.line(DVec3::new(0.0, 0.5, 2.0), DVec3::new(4.0, 0.5, 2.0), 1.0, [1.0, 0.0, 0.0]);
        let (_, _, rgb) = c.downsample(1);
        assert_eq!(&rgb[0..3], &[0, 0, 255], "behind the wall");
        let (w, h, rgb) = c.downsample(2);
        assert_eq!((w, h, rgb.len()), (2, 2, 12));
    }

    #[test]
    fn text_draws_the_glyphs() {
        let mut rgb = vec![0u8; 3 * 16 * 8];
        text(&mut rgb, 16, (0, 0), "I ", 1, [255, 255, 255]);
        let lit = |x0: usize, x1: usize| {
            (0..8)
                .flat_map(|y| (x0..x1).map(move |x| (x, y)))
                .filter(|&(x, y)| rgb[3 * (y * 16 + x)] == 255)
                .count()
        };
        assert!(lit(0, 8) > 5, "the I is drawn");
        assert_eq!(lit(8, 16), 0, "the space is blank");
    }
}
