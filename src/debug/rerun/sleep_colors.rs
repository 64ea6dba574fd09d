//! Sleeping shown in the recording: a sleeping body is drawn in a muted colour of its island,
//! each sleeping island its own hue (from its key), so a viewer sees which bodies sleep and which
//! sleep together (`crate::dynamics::islands`); awake bodies keep their kind's colour.

/// The colour of a body asleep in island `key`: hues a golden-ratio turn apart from key to key
/// (so islands that fell asleep one after the other differ), at low saturation and value.
pub(super) fn sleeping_color(key: u64) -> [u8; 3] {
    let hue = (key as f64 * 0.618_033_988_749_895).fract();
    hsv(hue, 0.35, 0.6)
}

/// A colour from hue, saturation and value, each in `[0, 1]`.
fn hsv(hue: f64, saturation: f64, value: f64) -> [u8; 3] {
    let sector = hue * 6.0;
    let f = sector.fract();
    let (p, q, t) = (
        value * (1.0 - saturation),
        value * (1.0 - saturation * f),
        value * (1.0 - saturation * (1.0 - f)),
    );
    let (r, g, b) = match sector as u32 % 6 {
        0 => (value, t, p),
        1 => (q, value, p),
        2 => (p, value, t),
        3 => (p, q, value),
        4 => (t, p, value),
        _ => (value, p, q),
    };
    [r, g, b].map(|c| (c * 255.0).round().clamp(0.0, 255.0) as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn consecutive_islands_get_distinct_muted_colours() {
        let colours: Vec<[u8; 3]> = (1..=8).map(sleeping_color).collect();
        for (i, a) in colours.iter().enumerate() {
            // Muted: no channel above the value 0.6 (153).
            assert!(a.iter().all(|&c| c <= 153), "{a:?}");
            for b in &colours[i + 1..] {
                let d: i32 = a
                    .iter()
                    .zip(b)
                    .map(|(x, y)| (*x as i32 - *y as i32).abs())
                    .sum();
                assert!(d > 20, "{a:?} vs {b:?}");
            }
        }
        assert_eq!(hsv(0.0, 0.0, 1.0), [255, 255, 255]);
        assert_eq!(hsv(0.0, 1.0, 1.0), [255, 0, 0]);
    }
}
