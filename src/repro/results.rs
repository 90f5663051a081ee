//! Raw measurements of a reproduction run, as written by `tables --out` and
//! read by `tables merge`: everything needed to merge shards and print the
//! tables without running anything again.
//!
//! Every measurement is a [`Sample`]: one group of runs (say "the traversal
//! variants over the flight"), one scene, one frame (or none for measurements
//! that do not depend on frames, which the shard starting at frame 0 takes),
//! one variant, and named counters. Tables sum samples over frames in frame
//! order, so a merged set of shards gives the same sums — and the same
//! printed tables, byte for byte — as one unsplit run.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::protocol::{FrameRange, Protocol, normalise};

/// The file format's version.
pub const FORMAT: u32 = 1;

/// One measurement.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sample {
    /// The measurement group (`fabianowski/traversal`).
    pub group: String,
    /// Scene.
    pub scene: String,
    /// Frame of the flight; `None` for frame-independent measurements.
    pub frame: Option<u32>,
    /// Variant, heuristic or setting.
    pub variant: String,
    /// Named counters.
    pub counters: BTreeMap<String, f64>,
}

/// A scene as run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SceneInfo {
    /// Name.
    pub name: String,
    /// Triangles.
    pub triangles: usize,
    /// The thesis' triangle count, if known.
    pub thesis_triangles: Option<u64>,
    /// Frames of its flight.
    pub flight_frames: u32,
    /// Frames measured (disjoint, sorted).
    pub frames: Vec<FrameRange>,
}

/// The raw measurements of one run or of merged shards.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Results {
    /// [`FORMAT`].
    pub format: u32,
    /// The commit of the warplight that measured.
    pub commit: String,
    /// The protocol.
    pub protocol: Protocol,
    /// Whether the emulated kernels ran with ptxas's FMA contraction
    /// (`tables --fmad`; on in files written before it was recorded, the
    /// only setting then). Shards merge only with the same.
    #[serde(default = "contraction_on")]
    pub fmad: bool,
    /// The tables asked for (addresses, `fabianowski:4.5`).
    pub tables: Vec<String>,
    /// The measurement groups run.
    pub groups: Vec<String>,
    /// Scenes, in the order run.
    pub scenes: Vec<SceneInfo>,
    /// Scenes of the tables that could not be run, with why.
    #[serde(default)]
    pub unavailable: Vec<String>,
    /// Samples, sorted by group, scene, frame, variant.
    pub samples: Vec<Sample>,
}

fn contraction_on() -> bool {
    true
}

/// Why shards cannot be merged, or a results file cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum MergeError {
    /// No file given.
    #[error("name the shard files to merge")]
    Empty,
    /// Unreadable file.
    #[error("{file}: {msg}")]
    Read {
        /// The file.
        file: String,
        /// What went wrong.
        msg: String,
    },
    /// Shards that do not belong together.
    #[error("{file} does not belong with {first}: {what}")]
    Mismatch {
        /// The first shard.
        first: String,
        /// The shard that differs.
        file: String,
        /// What differs.
        what: String,
    },
    /// The same frames measured twice.
    #[error("{scene}: frames {a} and {b} overlap (in {file}); each frame must come from one shard")]
    Overlap {
        /// Scene.
        scene: String,
        /// One range.
        a: FrameRange,
        /// The other.
        b: FrameRange,
        /// The shard that brought the second.
        file: String,
    },
    /// The same frame-independent measurement twice.
    #[error(
        "{scene}: {group} is in more than one shard (in {file}); only the shard that starts at frame 0 measures it"
    )]
    Duplicate {
        /// Scene.
        scene: String,
        /// Group.
        group: String,
        /// The shard that brought the second.
        file: String,
    },
    /// Frames of the protocol that no shard measured.
    #[error("{scene}: frames {missing} of the protocol are in no shard (run them, or merge with --partial)")]
    Gap {
        /// Scene.
        scene: String,
        /// The missing frames.
        missing: String,
    },
}

impl Results {
    /// An empty result for a run, with FMA contraction on (the run sets
    /// [`Results::fmad`] as it ran).
    pub fn new(commit: &str, protocol: Protocol, tables: Vec<String>, groups: Vec<String>) -> Results {
        Results {
            format: FORMAT,
            commit: commit.into(),
            protocol,
            fmad: true,
            tables,
            groups,
            scenes: Vec::new(),
            unavailable: Vec::new(),
            samples: Vec::new(),
        }
    }

    /// Sorts the samples into their canonical order.
    pub fn normalise(&mut self) {
        self.samples
            .sort_by(|a, b| (&a.group, &a.scene, a.frame, &a.variant).cmp(&(&b.group, &b.scene, b.frame, &b.variant)));
    }

    /// Scene info by name.
    pub fn scene(&self, name: &str) -> Option<&SceneInfo> {
        self.scenes.iter().find(|s| s.name == name)
    }

    /// Whether `group` has samples for `scene`.
    pub fn has(&self, group: &str, scene: &str) -> bool {
        self.samples.iter().any(|s| s.group == group && s.scene == scene)
    }

    /// The sum over frames (in frame order) of `counter` of `variant`, or
    /// `None` when nothing was measured.
    pub fn sum(&self, group: &str, scene: &str, variant: &str, counter: &str) -> Option<f64> {
        let mut any = false;
        let mut total = 0.0;
        for s in self.samples.iter().filter(|s| s.group == group && s.scene == scene && s.variant == variant) {
            if let Some(v) = s.counters.get(counter) {
                total += v;
                any = true;
            }
        }
        any.then_some(total)
    }

    /// `counter` of `variant` frame by frame: (frame, value).
    pub fn per_frame(&self, group: &str, scene: &str, variant: &str, counter: &str) -> Vec<(u32, f64)> {
        self.samples
            .iter()
            .filter(|s| s.group == group && s.scene == scene && s.variant == variant)
            .filter_map(|s| Some((s.frame?, *s.counters.get(counter)?)))
            .collect()
    }

    /// Frames measured for `scene`, as text (`0..3`, `0..10, 20..30`).
    pub fn frames_text(&self, scene: &str) -> String {
        self.scene(scene)
            .map(|s| s.frames.iter().map(|r| r.to_string()).collect::<Vec<_>>().join(", "))
            .unwrap_or_default()
    }

    /// Reads a results file.
    pub fn read(path: &std::path::Path) -> Result<Results, MergeError> {
        let file = path.display().to_string();
        let text =
            std::fs::read_to_string(path).map_err(|e| MergeError::Read { file: file.clone(), msg: e.to_string() })?;
        let r: Results = serde_json::from_str(&text)
            .map_err(|e| MergeError::Read { file: file.clone(), msg: format!("not a warplight results file ({e})") })?;
        if r.format != FORMAT {
            return Err(MergeError::Read {
                file,
                msg: format!("results format {} (this warplight reads format {FORMAT})", r.format),
            });
        }
        Ok(r)
    }

    /// Merges shards: same commit, protocol, FMA contraction, tables and
    /// groups; disjoint frames.
    /// With `partial == false`, every scene must cover the protocol's frames.
    pub fn merge(shards: &[(String, Results)], partial: bool) -> Result<Results, MergeError> {
        let Some((first_name, first)) = shards.first() else { return Err(MergeError::Empty) };
        let mut out = first.clone();
        out.scenes.clear();
        out.samples.clear();
        out.unavailable.clear();
        for (name, r) in shards {
            let mismatch = |what: String| MergeError::Mismatch { first: first_name.clone(), file: name.clone(), what };
            if r.commit != first.commit {
                return Err(mismatch(format!("measured by commit {} against {}", r.commit, first.commit)));
            }
            if r.protocol != first.protocol {
                return Err(mismatch(format!(
                    "protocol {} against {}",
                    r.protocol.describe(),
                    first.protocol.describe()
                )));
            }
            if r.fmad != first.fmad {
                let on = |f: bool| if f { "on" } else { "off" };
                return Err(mismatch(format!(
                    "FMA contraction {} against {} (tables --fmad)",
                    on(r.fmad),
                    on(first.fmad)
                )));
            }
            if r.tables != first.tables || r.groups != first.groups {
                return Err(mismatch(format!("tables {} against {}", r.tables.join(" "), first.tables.join(" "))));
            }
            for s in &r.scenes {
                match out.scenes.iter_mut().find(|x| x.name == s.name) {
                    None => out.scenes.push(s.clone()),
                    Some(x) => {
                        if (x.triangles, x.flight_frames) != (s.triangles, s.flight_frames) {
                            return Err(mismatch(format!("scene {} has other triangles or flight", s.name)));
                        }
                        for f in &s.frames {
                            if let Some(o) = x.frames.iter().find(|o| o.overlaps(f)) {
                                return Err(MergeError::Overlap {
                                    scene: s.name.clone(),
                                    a: *o,
                                    b: *f,
                                    file: name.clone(),
                                });
                            }
                        }
                        x.frames.extend(s.frames.iter().copied());
                        normalise(&mut x.frames).map_err(|(a, b)| MergeError::Overlap {
                            scene: s.name.clone(),
                            a,
                            b,
                            file: name.clone(),
                        })?;
                    }
                }
            }
            for s in r.samples.iter().filter(|s| s.frame.is_none()) {
                if out.samples.iter().any(|o| o.frame.is_none() && o.group == s.group && o.scene == s.scene) {
                    return Err(MergeError::Duplicate {
                        scene: s.scene.clone(),
                        group: s.group.clone(),
                        file: name.clone(),
                    });
                }
            }
            out.samples.extend(r.samples.iter().cloned());
            for u in &r.unavailable {
                if !out.unavailable.contains(u) {
                    out.unavailable.push(u.clone());
                }
            }
        }
        // scenes in the order of the protocol's scene list: as the first shard that ran them
        if !partial {
            for s in &out.scenes {
                let want = FrameRange::first(out.protocol.frames.min(s.flight_frames));
                let missing = gaps(want, &s.frames);
                if !missing.is_empty() {
                    return Err(MergeError::Gap {
                        scene: s.name.clone(),
                        missing: missing.iter().map(|r| r.to_string()).collect::<Vec<_>>().join(", "),
                    });
                }
            }
        }
        out.normalise();
        Ok(out)
    }
}

/// The parts of `want` not covered by `have` (sorted, disjoint).
fn gaps(want: FrameRange, have: &[FrameRange]) -> Vec<FrameRange> {
    let mut out = Vec::new();
    let mut at = want.start;
    for h in have {
        if h.start > at {
            out.push(FrameRange { start: at, end: h.start.min(want.end) });
        }
        at = at.max(h.end);
    }
    if at < want.end {
        out.push(FrameRange { start: at, end: want.end });
    }
    out.retain(|r| !r.is_empty());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shard(frames: FrameRange, with_builds: bool) -> Results {
        let mut r = Results::new("abc", Protocol::quick(), vec!["t:1".into()], vec!["g".into()]);
        r.scenes.push(SceneInfo {
            name: "s".into(),
            triangles: 10,
            thesis_triangles: None,
            flight_frames: 50,
            frames: vec![frames],
        });
        for f in frames.start..frames.end {
            r.samples.push(Sample {
                group: "g".into(),
                scene: "s".into(),
                frame: Some(f),
                variant: "v".into(),
                counters: [("rays".to_string(), 0.1 * f as f64 + 1.0)].into(),
            });
        }
        if with_builds {
            r.samples.push(Sample {
                group: "b".into(),
                scene: "s".into(),
                frame: None,
                variant: "v".into(),
                counters: BTreeMap::new(),
            });
        }
        r.normalise();
        r
    }

    #[test]
    fn shards_merge_to_the_unsplit_run() {
        let whole = shard(FrameRange::first(3), true);
        let a = shard(FrameRange { start: 0, end: 1 }, true);
        let b = shard(FrameRange { start: 1, end: 3 }, false);
        let m = Results::merge(&[("b".into(), b.clone()), ("a".into(), a.clone())], false).unwrap();
        assert_eq!(m.samples, whole.samples);
        assert_eq!(m.scenes, whole.scenes);
        assert_eq!(m.sum("g", "s", "v", "rays"), whole.sum("g", "s", "v", "rays"));
        // overlapping frames, the frame-independent group twice, a gap, another protocol
        let e = Results::merge(&[("a".into(), a.clone()), ("a2".into(), a.clone())], false).unwrap_err();
        assert!(matches!(e, MergeError::Overlap { .. }), "{e}");
        let gap = Results::merge(&[("b".into(), b.clone())], false).unwrap_err();
        assert_eq!(
            gap.to_string(),
            "s: frames 0..1 of the protocol are in no shard (run them, or merge with --partial)"
        );
        assert!(Results::merge(&[("b".into(), b.clone())], true).is_ok());
        let mut c = b.clone();
        c.protocol = Protocol::thesis();
        let e = Results::merge(&[("a".into(), a.clone()), ("c".into(), c)], false).unwrap_err();
        assert!(e.to_string().contains("protocol thesis: 50 frame(s)"), "{e}");
        let mut d = b;
        d.commit = "def".into();
        let e = Results::merge(&[("a".into(), a), ("d".into(), d)], false).unwrap_err();
        assert!(e.to_string().contains("commit def"), "{e}");
    }
}
