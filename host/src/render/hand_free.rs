//! Frames with no hand in them: the background's grey, optional noise, optional clutter
//! (bright and dark bars at every angle), from a small deterministic generator. The search
//! must never claim a hand on them (`tests/tests/probation.rs`, `acquire_probe
//! --hand-free-status`).

/// A hand-free frame: the background's grey, optional noise, optional clutter (bright and
/// dark bars at every angle), from a small deterministic generator.
pub fn hand_free(
    width: usize,
    height: usize,
    grey: u8,
    noise: u8,
    clutter: bool,
    seed: u64,
) -> Vec<u8> {
    let mut state = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 33) as u32
    };
    let mut pixels = vec![grey; width * height];
    if clutter {
        for _ in 0..25 {
            let (cx, cy) = (next() as usize % width, next() as usize % height);
            let angle = (next() % 360) as f32 * std::f32::consts::PI / 180.0;
            let (len, half) = (20 + next() as usize % 80, 2 + next() as usize % 5);
            let level = if next() % 2 == 0 { 230 } else { 20 };
            for t in 0..len {
                for w in 0..2 * half {
                    let x =
                        cx as f32 + angle.cos() * t as f32 - angle.sin() * (w as f32 - half as f32);
                    let y =
                        cy as f32 + angle.sin() * t as f32 + angle.cos() * (w as f32 - half as f32);
                    if x >= 0.0 && y >= 0.0 && (x as usize) < width && (y as usize) < height {
                        pixels[y as usize * width + x as usize] = level;
                    }
                }
            }
        }
    }
    if noise > 0 {
        for p in &mut pixels {
            let n = (next() % (2 * u32::from(noise) + 1)) as i32 - i32::from(noise);
            *p = (i32::from(*p) + n).clamp(0, 255) as u8;
        }
    }
    pixels
}

/// The four kinds of hand-free frame, taken in turn: (noise amplitude, clutter).
pub const KINDS: [(u8, bool); 4] = [(0, false), (8, false), (8, true), (0, true)];

/// Hand-free frame `k` of a run, one image per camera of `sizes` (width, height): the kind
/// `KINDS[k % 4]`, its grey and its generator's seed changing with `k` (and the camera).
pub fn hand_free_frame(sizes: &[(usize, usize)], k: usize) -> Vec<Vec<u8>> {
    let (noise, clutter) = KINDS[k % KINDS.len()];
    sizes
        .iter()
        .enumerate()
        .map(|(c, &(w, h))| {
            hand_free(
                w,
                h,
                30 + (k * 7 % 40) as u8,
                noise,
                clutter,
                (4 * k + c) as u64,
            )
        })
        .collect()
}
