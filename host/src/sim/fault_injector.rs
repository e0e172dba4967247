//! Line noise for robustness tests, as a fault injector in smoltcp's manner
//! (`smoltcp::phy::FaultInjector`): an embedded-io serial port wrapped around another, which
//! flips one random bit in a fraction of the bytes crossing it, both ways, during a window.
//! The port below knows nothing of it; the one above (the board) sees a noisy line.

use std::ops::Range;
use std::time::{Duration, Instant};

use embedded_io::{ErrorType, Read, ReadReady, Write};

/// When the line is noisy.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Window {
    /// All the time.
    Always,
    /// While frames with these numbers are uploaded: inbound, the bytes of `FrameChunk`s of
    /// these frames (and any other message sent meanwhile); outbound, every byte the board
    /// sends while the last frame it received is one of these.
    Frames(Range<u32>),
    /// For these bytes of each direction, counted from 0 since the simulator started.
    Bytes(Range<u64>),
    /// For this span of time since the simulator started.
    Time(Range<Duration>),
}

/// Flip one random bit in a fraction `rate` of the bytes crossing the line during `window`.
#[derive(Debug, Clone, PartialEq)]
pub struct Corruption {
    /// Fraction of the bytes hit (0–1), in each direction.
    pub rate: f64,
    /// When.
    pub window: Window,
    /// Seed of the noise, so a failing run can be repeated.
    pub seed: u64,
}

impl Corruption {
    /// `rate` of the bytes, all the time, seed 1.
    pub fn always(rate: f64) -> Self {
        Corruption {
            rate,
            window: Window::Always,
            seed: 1,
        }
    }
}

/// What a [`FaultInjector`] asks the port below it for [`Window::Frames`]: the number of the
/// frame whose upload the bytes now read belong to (the last one begun), if any.
pub trait UploadedFrame {
    /// The frame being uploaded, or `None` before the first.
    fn uploaded_frame(&self) -> Option<u32>;
}

/// Bytes a [`FaultInjector`] corrupted, per direction.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Injected {
    /// Bytes read (host to board) that were hit.
    pub corrupted_in: u64,
    /// Bytes written (board to host) that were hit.
    pub corrupted_out: u64,
}

/// A serial port with line noise: `S`'s bytes, some of them with one bit flipped
/// ([`Corruption`]). Without a corruption it passes everything through untouched.
pub struct FaultInjector<S> {
    inner: S,
    noise: Option<(Corruption, Noise)>,
    started: Instant,
    /// Bytes read through the injector so far (the next one's index, for [`Window::Bytes`]).
    bytes_in: u64,
    /// Bytes written through it so far.
    bytes_out: u64,
    injected: Injected,
}

impl<S> FaultInjector<S> {
    /// `inner` with `corruption` (none: a clean line).
    pub fn new(inner: S, corruption: Option<Corruption>) -> Self {
        let noise = corruption.map(|c| {
            let noise = Noise::new(c.seed, c.rate);
            (c, noise)
        });
        FaultInjector {
            inner,
            noise,
            started: Instant::now(),
            bytes_in: 0,
            bytes_out: 0,
            injected: Injected::default(),
        }
    }

    /// The port below.
    pub fn inner(&self) -> &S {
        &self.inner
    }

    /// The port below, mutably (bytes read or written through it bypass the noise).
    pub fn inner_mut(&mut self) -> &mut S {
        &mut self.inner
    }

    /// What the injector has corrupted so far.
    pub fn injected(&self) -> Injected {
        self.injected
    }
}

impl<S: UploadedFrame> FaultInjector<S> {
    /// Corrupts `bytes`, the next ones of a direction whose count so far is `*count`;
    /// returns how many were hit.
    fn corrupt(&mut self, bytes: &mut [u8], outbound: bool) -> u64 {
        let frame = self.inner.uploaded_frame();
        let count = if outbound {
            &mut self.bytes_out
        } else {
            &mut self.bytes_in
        };
        let first = *count;
        *count += bytes.len() as u64;
        let Some((corruption, noise)) = &mut self.noise else {
            return 0;
        };
        let mut hits = 0;
        for (i, byte) in bytes.iter_mut().enumerate() {
            let at = Position {
                byte: first + i as u64,
                frame,
                elapsed: self.started.elapsed(),
            };
            if corruption.window.contains(at) && noise.hit(byte) {
                hits += 1;
            }
        }
        hits
    }
}

impl<S: ErrorType> ErrorType for FaultInjector<S> {
    type Error = S::Error;
}

impl<S: Read + UploadedFrame> Read for FaultInjector<S> {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, S::Error> {
        let n = self.inner.read(buf)?;
        let hits = self.corrupt(&mut buf[..n], false);
        self.injected.corrupted_in += hits;
        Ok(n)
    }
}

impl<S: ReadReady> ReadReady for FaultInjector<S> {
    fn read_ready(&mut self) -> Result<bool, S::Error> {
        self.inner.read_ready()
    }
}

impl<S: Write + UploadedFrame> Write for FaultInjector<S> {
    /// Writes all of `buf` (corrupted) or fails: a partial write would make the caller resend
    /// bytes the noise has already drawn for.
    fn write(&mut self, buf: &[u8]) -> Result<usize, S::Error> {
        let mut bytes = buf.to_vec();
        let hits = self.corrupt(&mut bytes, true);
        self.injected.corrupted_out += hits;
        self.inner.write_all(&bytes)?;
        Ok(buf.len())
    }

    fn flush(&mut self) -> Result<(), S::Error> {
        self.inner.flush()
    }
}

/// Where on the line a byte is, for deciding whether the window is open.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Position {
    /// The byte's index in its direction.
    pub byte: u64,
    /// The frame the window test should use (see [`Window::Frames`]).
    pub frame: Option<u32>,
    /// Time since the injector started.
    pub elapsed: Duration,
}

impl Window {
    pub(crate) fn contains(&self, at: Position) -> bool {
        match self {
            Window::Always => true,
            Window::Frames(frames) => at.frame.is_some_and(|f| frames.contains(&f)),
            Window::Bytes(bytes) => bytes.contains(&at.byte),
            Window::Time(span) => span.contains(&at.elapsed),
        }
    }
}

/// The noise source: SplitMix64, so runs repeat exactly from a seed.
#[derive(Debug, Clone)]
pub(crate) struct Noise {
    state: u64,
    threshold: u64,
}

impl Noise {
    pub(crate) fn new(seed: u64, rate: f64) -> Self {
        let rate = if rate.is_finite() {
            rate.clamp(0.0, 1.0)
        } else {
            0.0
        };
        // rate 1.0 saturates to u64::MAX: every byte but one in 2^64.
        let threshold = (rate * u64::MAX as f64) as u64;
        Noise {
            state: seed,
            threshold,
        }
    }

    fn next(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Flips one bit of `byte` with the configured probability; says whether it did.
    pub(crate) fn hit(&mut self, byte: &mut u8) -> bool {
        let draw = self.next();
        if draw >= self.threshold {
            return false;
        }
        *byte ^= 1 << (self.next() % 8);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::convert::Infallible;

    /// A port that reads `input` and records what is written, uploading frame `frame`.
    struct Memory {
        input: Vec<u8>,
        output: Vec<u8>,
        frame: Option<u32>,
    }

    impl ErrorType for Memory {
        type Error = Infallible;
    }

    impl Read for Memory {
        fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
            let n = buf.len().min(self.input.len());
            buf[..n].copy_from_slice(&self.input[..n]);
            self.input.drain(..n);
            Ok(n)
        }
    }

    impl Write for Memory {
        fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
            // One byte at a time, so the injector's write_all is exercised.
            self.output.extend(buf.first());
            Ok(buf.len().min(1))
        }

        fn flush(&mut self) -> Result<(), Infallible> {
            Ok(())
        }
    }

    impl UploadedFrame for Memory {
        fn uploaded_frame(&self) -> Option<u32> {
            self.frame
        }
    }

    fn memory(frame: Option<u32>) -> Memory {
        Memory {
            input: vec![0; 64],
            output: Vec::new(),
            frame,
        }
    }

    #[test]
    fn bytes_in_the_window_are_hit_both_ways_and_the_rest_pass_untouched() {
        let window = Corruption {
            rate: 1.0,
            window: Window::Bytes(10..20),
            seed: 5,
        };
        let mut port = FaultInjector::new(memory(None), Some(window));
        let mut read = [0u8; 64];
        // In pieces: the byte count carries over from one read to the next.
        let first = port.read(&mut read[..15]).unwrap();
        let rest = port.read(&mut read[15..]).unwrap();
        assert_eq!(first + rest, 64);
        port.write_all(&[0u8; 64]).unwrap();
        for (bytes, way) in [(&read[..], "read"), (&port.inner().output[..], "written")] {
            for (i, b) in bytes.iter().enumerate() {
                let hit = (10..20).contains(&i);
                assert_eq!(b.count_ones(), u32::from(hit), "byte {i} {way}: {b:#04x}");
            }
        }
        assert_eq!(
            port.injected(),
            Injected {
                corrupted_in: 10,
                corrupted_out: 10
            }
        );
    }

    #[test]
    fn a_frame_window_follows_the_frame_below_and_no_corruption_is_a_clean_line() {
        let frames = Corruption {
            rate: 1.0,
            window: Window::Frames(3..5),
            seed: 5,
        };
        let mut buf = [0u8; 8];
        let mut outside = FaultInjector::new(memory(Some(5)), Some(frames.clone()));
        outside.read(&mut buf).unwrap();
        assert_eq!(buf, [0; 8]);
        let mut inside = FaultInjector::new(memory(Some(4)), Some(frames));
        inside.read(&mut buf).unwrap();
        assert!(buf.iter().all(|b| b.count_ones() == 1), "{buf:?}");
        let mut clean = FaultInjector::new(memory(Some(4)), None);
        clean.read(&mut buf).unwrap();
        clean.write_all(&[7; 8]).unwrap();
        assert_eq!((buf, &clean.inner().output[..]), ([0; 8], &[7u8; 8][..]));
        assert_eq!(clean.injected(), Injected::default());
    }

    #[test]
    fn the_rate_is_the_fraction_of_bytes_hit() {
        let mut noise = Noise::new(7, 0.01);
        let mut hits = 0;
        for _ in 0..200_000 {
            let mut b = 0u8;
            if noise.hit(&mut b) {
                assert_eq!(b.count_ones(), 1, "one bit flipped");
                hits += 1;
            }
        }
        assert!((1800..2200).contains(&hits), "{hits} of 200000 at 1%");
        let mut never = Noise::new(7, 0.0);
        assert!((0..10_000).all(|_| !never.hit(&mut 0)));
    }

    #[test]
    fn windows() {
        let at = |byte, frame, ms| Position {
            byte,
            frame,
            elapsed: Duration::from_millis(ms),
        };
        assert!(Window::Frames(3..5).contains(at(0, Some(4), 0)));
        assert!(!Window::Frames(3..5).contains(at(0, Some(5), 0)));
        assert!(!Window::Frames(3..5).contains(at(0, None, 0)));
        assert!(Window::Bytes(10..20).contains(at(10, None, 0)));
        assert!(!Window::Bytes(10..20).contains(at(20, None, 0)));
        let span = Duration::from_millis(100)..Duration::from_millis(200);
        assert!(Window::Time(span.clone()).contains(at(0, None, 150)));
        assert!(!Window::Time(span).contains(at(0, None, 250)));
    }
}
