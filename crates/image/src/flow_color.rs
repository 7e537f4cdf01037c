//! The Middlebury colour coding of optical flow (Baker et al. 2011, "A Database and Evaluation
//! Methodology for Optical Flow"; the `flow_vis` and KITTI development kits use the same
//! wheel): the direction is the hue on a 55-colour wheel (right red-magenta, down yellow, left
//! cyan, up blue-violet), the length the saturation, white for no motion, darkened beyond the
//! normalising length.

/// The colour wheel's segments: red-yellow, yellow-green, green-cyan, cyan-blue,
/// blue-magenta, magenta-red, with their numbers of colours.
const SEGMENTS: [usize; 6] = [15, 6, 4, 11, 13, 6];

/// Colour `i` of the 55-colour wheel, 0-255 per channel.
fn wheel(i: usize) -> [f32; 3] {
    let mut k = i;
    for (s, &n) in SEGMENTS.iter().enumerate() {
        if k < n {
            let up = (255 * k / n) as f32;
            let down = 255.0 - up;
            return match s {
                0 => [255.0, up, 0.0],
                1 => [down, 255.0, 0.0],
                2 => [0.0, 255.0, up],
                3 => [0.0, down, 255.0],
                4 => [up, 0.0, 255.0],
                _ => [255.0, 0.0, down],
            };
        }
        k -= n;
    }
    [255.0, 0.0, 0.0]
}

/// The colour of the flow `(u, v)` (pixels, image y down) normalised by `max_radius`: white
/// at rest, the wheel's hue at full saturation at `max_radius`, darkened to 75 % beyond it.
/// A flow that is not finite, or a `max_radius` that is not positive, is black.
pub fn flow_color(u: f32, v: f32, max_radius: f32) -> [u8; 3] {
    if !(u.is_finite() && v.is_finite() && max_radius > 0.0) {
        return [0, 0, 0];
    }
    let n: usize = SEGMENTS.iter().sum();
    let (u, v) = (u / max_radius, v / max_radius);
    let rad = (u * u + v * v).sqrt();
    let a = (-v).atan2(-u) / std::f32::consts::PI;
    let fk = (a + 1.0) / 2.0 * (n - 1) as f32;
    let k0 = (fk.floor() as usize).min(n - 1);
    let k1 = (k0 + 1) % n;
    let f = fk - k0 as f32;
    let (c0, c1) = (wheel(k0), wheel(k1));
    let mut out = [0u8; 3];
    for c in 0..3 {
        let col = ((1.0 - f) * c0[c] + f * c1[c]) / 255.0;
        let col = if rad <= 1.0 {
            1.0 - rad * (1.0 - col)
        } else {
            col * 0.75
        };
        out[c] = (255.0 * col).floor().clamp(0.0, 255.0) as u8;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Equal within 1 (the wheel's floor of a mean of two colours may land either side).
    fn near(a: [u8; 3], b: [u8; 3]) -> bool {
        a.iter().zip(b).all(|(x, y)| x.abs_diff(y) <= 1)
    }

    /// The wheel's colours at the four directions, worked out by hand from its segments
    /// (`atan2(-v, -u)`: a rightward flow has angle -pi, colour 0): right is colour 0 (red),
    /// left colour 27 (cyan-blue 2 of 11: green 255 - 46), down half way between colours 13
    /// and 14 (red-yellow: green 221 and 238), up half way between 40 and 41 (blue-magenta:
    /// red 78 and 98).
    #[test]
    fn directions_get_the_middlebury_hues() {
        for ((u, v, r), expected) in [
            ((1.0, 0.0, 1.0), [255, 0, 0]),
            ((-2.0, 0.0, 2.0), [0, 209, 255]),
            ((0.0, 1.0, 1.0), [255, 229, 0]),
            ((0.0, -1.0, 1.0), [88, 0, 255]),
            // At rest white, half way half saturated, beyond the radius darker.
            ((0.0, 0.0, 1.0), [255, 255, 255]),
            ((0.5, 0.0, 1.0), [255, 127, 127]),
            ((2.0, 0.0, 1.0), [191, 0, 0]),
        ] {
            let got = flow_color(u, v, r);
            assert!(near(got, expected), "({u}, {v}): {got:?} vs {expected:?}");
        }
        assert_eq!(flow_color(f32::INFINITY, 0.0, 1.0), [0, 0, 0]);
        assert_eq!(flow_color(1.0, 0.0, 0.0), [0, 0, 0]);
    }
}
