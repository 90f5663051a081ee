//! Protocols (how much of a thesis' experiment a run repeats) and frame
//! ranges (which part of it one shard runs).

use serde::{Deserialize, Serialize};

/// Frames of each camera flight and the image side.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Protocol {
    /// `quick`, `thesis`, or `custom` when `--frames N`/`--resolution` changed one.
    pub name: String,
    /// Frames of each flight (a scene whose flight is shorter runs all of its own).
    pub frames: u32,
    /// Image side in pixels.
    pub resolution: u32,
}

impl Protocol {
    /// A few frames at a small resolution: minutes for a whole chapter.
    pub fn quick() -> Protocol {
        Protocol { name: "quick".into(), frames: 3, resolution: 96 }
    }

    /// The published protocol of thesis 000 ch. 4: 50 frames at 512 × 512 (§A.2).
    pub fn thesis() -> Protocol {
        Protocol { name: "thesis".into(), frames: 50, resolution: 512 }
    }

    /// By name.
    pub fn named(name: &str) -> Result<Protocol, String> {
        match name {
            "quick" => Ok(Protocol::quick()),
            "thesis" => Ok(Protocol::thesis()),
            other => Err(format!("--protocol {other}: expected quick or thesis")),
        }
    }

    /// With frames and/or resolution overridden (the name becomes `custom`).
    pub fn with(mut self, frames: Option<u32>, resolution: Option<u32>) -> Protocol {
        if let Some(f) = frames.filter(|f| *f != self.frames) {
            self.frames = f;
            self.name = "custom".into();
        }
        if let Some(r) = resolution.filter(|r| *r != self.resolution) {
            self.resolution = r;
            self.name = "custom".into();
        }
        self
    }

    /// One line: `quick: 3 frames at 96x96`.
    pub fn describe(&self) -> String {
        format!("{}: {} frame(s) of each flight at {}x{}", self.name, self.frames, self.resolution, self.resolution)
    }
}

/// Frames `start..end` (half open) of each flight.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub struct FrameRange {
    /// First frame.
    pub start: u32,
    /// One past the last.
    pub end: u32,
}

impl FrameRange {
    /// `0..n`.
    pub fn first(n: u32) -> FrameRange {
        FrameRange { start: 0, end: n }
    }

    /// Parses `A..B` (half open, as Rust writes ranges).
    pub fn parse(s: &str) -> Result<FrameRange, String> {
        let (a, b) = s.split_once("..").ok_or_else(|| format!("--frames {s}: expected N or A..B"))?;
        let p = |x: &str| x.trim().parse::<u32>().map_err(|_| format!("--frames {s}: {x:?} is not a frame number"));
        let r = FrameRange { start: p(a)?, end: p(b)? };
        if r.start >= r.end {
            return Err(format!("--frames {s}: the range is empty (A..B runs frames A to B-1)"));
        }
        Ok(r)
    }

    /// Clipped to a flight of `n` frames (may become empty).
    pub fn clip(&self, n: u32) -> FrameRange {
        FrameRange { start: self.start.min(n), end: self.end.min(n) }
    }

    /// Frames in the range.
    pub fn len(&self) -> u32 {
        self.end.saturating_sub(self.start)
    }

    /// Whether it holds no frame.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether two ranges share a frame.
    pub fn overlaps(&self, o: &FrameRange) -> bool {
        self.start < o.end && o.start < self.end
    }
}

impl std::fmt::Display for FrameRange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}..{}", self.start, self.end)
    }
}

/// Sorts ranges and joins touching ones; returns the first overlap as an error.
pub fn normalise(ranges: &mut Vec<FrameRange>) -> Result<(), (FrameRange, FrameRange)> {
    ranges.sort();
    let mut out: Vec<FrameRange> = Vec::new();
    for r in ranges.iter().copied().filter(|r| !r.is_empty()) {
        match out.last_mut() {
            Some(last) if last.overlaps(&r) => return Err((*last, r)),
            Some(last) if last.end == r.start => last.end = r.end,
            _ => out.push(r),
        }
    }
    *ranges = out;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_parse_clip_and_join() {
        assert_eq!(FrameRange::parse("10..20"), Ok(FrameRange { start: 10, end: 20 }));
        assert!(FrameRange::parse("5..5").is_err());
        assert!(FrameRange::parse("a..5").is_err());
        assert!(FrameRange::parse("5").is_err());
        assert_eq!(FrameRange::parse("40..60").unwrap().clip(50), FrameRange { start: 40, end: 50 });
        let mut v = vec![FrameRange { start: 2, end: 4 }, FrameRange { start: 0, end: 2 }];
        normalise(&mut v).unwrap();
        assert_eq!(v, vec![FrameRange { start: 0, end: 4 }]);
        let mut w = vec![FrameRange { start: 0, end: 3 }, FrameRange { start: 2, end: 4 }];
        assert!(normalise(&mut w).is_err());
    }

    #[test]
    fn overriding_a_protocol_names_it_custom() {
        assert_eq!(Protocol::quick().with(Some(3), None).name, "quick");
        assert_eq!(Protocol::quick().with(None, Some(32)).name, "custom");
        assert_eq!(Protocol::thesis().with(Some(50), Some(512)), Protocol::thesis());
    }
}
