//! How a body is coloured in the recording: by kind (dynamic, kinematic, static; a part of a
//! compound by its root's kind), quarantined red, by its own [`DebugColor`] if it has one, and,
//! asleep, in a muted colour of its island: each sleeping island its own hue (from its key), so
//! a viewer sees which bodies sleep and which sleep together (`crate::dynamics::islands`).

use super::DebugColor;
use crate::components::{ComputedMass, Quarantined, Static};
use bevy_ecs::prelude::*;

const DYNAMIC: [u8; 3] = [230, 126, 34];
const KINEMATIC: [u8; 3] = [52, 152, 219];
pub(super) const STATIC: [u8; 3] = [149, 165, 166];
const QUARANTINED: [u8; 3] = [231, 76, 60];

/// What decides a body's colour: whether it (or, for a part, its root) is static, its mass, and
/// whether it is quarantined.
pub(super) type KindView<'a> = (Has<Static>, Option<&'a ComputedMass>, Has<Quarantined>);

/// The colour of a body's kind from whether it is static and its mass.
pub(super) fn kind_tint(is_static: bool, mass: Option<&ComputedMass>) -> [u8; 3] {
    match mass {
        _ if is_static => STATIC,
        Some(m) if m.inverse() == 0.0 => KINEMATIC,
        _ => DYNAMIC,
    }
}

/// The colour of `e`: quarantined red; asleep (in island `sleeping`), its island's; else its
/// own tint, or its root's kind (a wheel is drawn like its car).
pub(super) fn body_color(
    e: Entity,
    tint: Option<&DebugColor>,
    sleeping: Option<u64>,
    parents: &Query<&ChildOf>,
    kinds: &Query<KindView>,
) -> [u8; 3] {
    if matches!(kinds.get(e), Ok((_, _, true))) {
        return QUARANTINED;
    }
    match (tint, sleeping) {
        (_, Some(island)) => sleeping_color(island),
        (Some(t), _) => t.0,
        _ => {
            let mut root = e;
            for _ in 0..crate::plugins::validation::MAX_HIERARCHY_DEPTH {
                match parents.get(root) {
                    Ok(p) => root = p.parent(),
                    Err(_) => break,
                }
            }
            kinds
                .get(root)
                .map_or(DYNAMIC, |(is_static, mass, _)| kind_tint(is_static, mass))
        }
    }
}

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
