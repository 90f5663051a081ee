//! Planning and running a reproduction: which measurement groups the asked
//! tables need, on which scenes and frames, how long that should take, and
//! the run itself into raw [`Results`].

use super::protocol::{FrameRange, Protocol};
use super::registry::{Entry, Group, Tick, Workspace, tree_seconds_per_triangle};
use super::results::{Results, SceneInfo};
use crate::host::kdtree::Heuristic;
use crate::host::scene::Scene;

/// A scene that could not be run.
#[derive(Debug, Clone)]
pub struct Unavailable {
    /// Its name.
    pub name: String,
    /// Why (the loader's error, naming the file).
    pub why: String,
}

/// What a run will do.
#[derive(Debug)]
pub struct Plan {
    /// The tables.
    pub entries: Vec<Entry>,
    /// The measurement groups they need, each with the scenes it runs on.
    pub groups: Vec<(&'static Group, Vec<String>)>,
    /// The protocol.
    pub protocol: Protocol,
    /// The frames of this run (a shard runs part of the protocol's).
    pub frames: FrameRange,
    /// Repetitions of timed builds.
    pub repeats: u32,
}

impl Plan {
    /// Plans `entries` under `protocol`; `scenes` overrides the tables' scenes;
    /// `frames` selects a shard (default: all of the protocol's frames).
    pub fn new(
        entries: Vec<Entry>,
        scenes: &[String],
        protocol: Protocol,
        frames: Option<FrameRange>,
        repeats: u32,
    ) -> Plan {
        let mut groups: Vec<(&'static Group, Vec<String>)> = Vec::new();
        for e in &entries {
            for g in e.groups() {
                let want: Vec<String> = if scenes.is_empty() {
                    e.table.scenes.iter().map(|s| s.to_string()).collect()
                } else {
                    scenes.to_vec()
                };
                match groups.iter_mut().find(|(x, _)| x.name == g.name) {
                    Some((_, s)) => {
                        for w in want {
                            if !s.contains(&w) {
                                s.push(w);
                            }
                        }
                    }
                    None => groups.push((g, want)),
                }
            }
        }
        let frames = frames.unwrap_or(FrameRange::first(protocol.frames)).clip(protocol.frames);
        Plan { entries, groups, protocol, frames, repeats }
    }

    /// Every scene of the plan, in first-use order.
    pub fn scenes(&self) -> Vec<String> {
        let mut v: Vec<String> = Vec::new();
        for (_, s) in &self.groups {
            for n in s {
                if !v.contains(n) {
                    v.push(n.clone());
                }
            }
        }
        v
    }

    /// Whether this run takes the frame-independent measurements (the shard starting at frame 0 does).
    pub fn takes_frame_independent(&self) -> bool {
        self.frames.start == 0
    }

    /// Frames of `scene`'s flight this run covers.
    fn frames_of(&self, scene: &Scene) -> FrameRange {
        self.frames.clip(scene.flight.frames)
    }

    /// Progress units (frames × variants, or variants for frame-independent groups).
    pub fn units(&self, scenes: &[Scene]) -> u64 {
        self.work(
            scenes,
            |g, _, frames| if g.per_frame { (frames * g.variants as u64) as f64 } else { g.variants as f64 },
        ) as u64
    }

    /// Estimated seconds on `threads` threads: frames run in parallel, tree builds do not.
    pub fn seconds(&self, scenes: &[Scene], threads: usize) -> f64 {
        let frames = self.work(scenes, |g, _, frames| {
            let runs = if g.per_frame { frames as f64 } else { 1.0 } * g.variants as f64;
            // the side it runs at: the protocol's, capped, or its own
            let side = g.side.of(self.protocol.resolution);
            runs * side as f64 * g.seconds_per_side
        });
        let own = self.work(scenes, |g, s, _| s.triangles.len() as f64 * g.seconds_per_triangle);
        let mut trees = 0.0;
        for s in scenes {
            let mut hs: Vec<Heuristic> = Vec::new();
            for (g, _) in self.groups.iter().filter(|(g, names)| self.runs(g, names, s)) {
                for h in g.trees {
                    if !hs.contains(h) {
                        hs.push(*h);
                    }
                }
            }
            trees += hs.iter().map(|h| tree_seconds_per_triangle(*h) * s.triangles.len() as f64).sum::<f64>();
        }
        frames / threads.max(1) as f64 + own + trees
    }

    /// Whether group `g` (on scenes `names`) runs on `s` in this run.
    fn runs(&self, g: &Group, names: &[String], s: &Scene) -> bool {
        names.contains(&s.name) && (g.per_frame || self.takes_frame_independent())
    }

    /// The sum of `f(group, scene, frames)` over the groups and scenes this run runs.
    fn work(&self, scenes: &[Scene], f: impl Fn(&Group, &Scene, u64) -> f64) -> f64 {
        let mut total = 0.0;
        for s in scenes {
            for (g, names) in &self.groups {
                if self.runs(g, names, s) {
                    total += f(g, s, self.frames_of(s).len() as u64);
                }
            }
        }
        total
    }

    /// The plan in words, with the estimate: printed before a run starts.
    pub fn describe(&self, scenes: &[Scene], unavailable: &[Unavailable], threads: usize) -> String {
        let addr: Vec<String> = self.entries.iter().map(|e| e.address()).collect();
        let mut s = format!("warplight tables: {}\n", addr.join(" "));
        s.push_str(&format!("  protocol {}; this run: frames {}\n", self.protocol.describe(), self.frames));
        for (g, names) in &self.groups {
            let run: Vec<&str> = scenes.iter().filter(|s| names.contains(&s.name)).map(|s| s.name.as_str()).collect();
            let when = if g.per_frame {
                String::new()
            } else if self.takes_frame_independent() {
                " (once per scene)".into()
            } else {
                " (not in this shard: the shard starting at frame 0 takes it)".into()
            };
            let cap = g.side.note(self.protocol.resolution);
            s.push_str(&format!("  {}: {} on {}{when}{cap}\n", g.name, g.what, run.join(", ")));
        }
        for u in unavailable {
            s.push_str(&format!("  unavailable: {}\n", u.why));
        }
        let secs = self.seconds(scenes, threads);
        s.push_str(&format!("  estimated time: {} on {threads} thread(s)\n", human(secs)));
        s
    }
}

/// Seconds as `40 s`, `12 min`, `3.5 h`.
pub fn human(secs: f64) -> String {
    if secs < 90.0 {
        format!("{} s", secs.round().max(1.0))
    } else if secs < 5400.0 {
        format!("{} min", (secs / 60.0).round())
    } else {
        format!("{:.1} h", secs / 3600.0)
    }
}

/// Progress of a run.
pub struct Progress<'a> {
    /// Scene.
    pub scene: &'a str,
    /// Group.
    pub group: &'a str,
    /// Frame, if per frame.
    pub frame: Option<u32>,
    /// Variant.
    pub variant: &'a str,
}

/// Runs the plan on the loaded scenes.
pub fn execute(
    plan: &Plan,
    scenes: &[Scene],
    unavailable: &[Unavailable],
    commit: &str,
    progress: &mut dyn FnMut(Progress),
) -> Result<Results, String> {
    let addr: Vec<String> = plan.entries.iter().map(|e| e.address()).collect();
    let groups: Vec<String> = plan.groups.iter().map(|(g, _)| g.name.to_string()).collect();
    let mut r = Results::new(commit, plan.protocol.clone(), addr, groups);
    // the emulated kernels' contraction, as `tables --fmad` set it for the process
    r.fmad = crate::sim::contract::default_on();
    r.unavailable = unavailable.iter().map(|u| u.why.clone()).collect();
    for s in scenes {
        let frames = plan.frames_of(s);
        let mut ws = Workspace::new(s, frames.start..frames.end, plan.protocol.resolution);
        ws.repeats = plan.repeats;
        let mut ran = false;
        for (g, names) in &plan.groups {
            if !plan.runs(g, names, s) || (g.per_frame && frames.is_empty()) {
                continue;
            }
            let mut tick =
                |t: Tick| progress(Progress { scene: &s.name, group: g.name, frame: t.frame, variant: t.variant });
            let samples = (g.measure)(&mut ws, &mut tick).map_err(|e| format!("{} on {}: {e}", g.name, s.name))?;
            r.samples.extend(samples);
            ran = true;
        }
        if ran {
            r.scenes.push(SceneInfo {
                name: s.name.clone(),
                triangles: s.triangles.len(),
                thesis_triangles: s.thesis.map(|t| t.triangles),
                flight_frames: s.flight.frames,
                frames: if frames.is_empty() { Vec::new() } else { vec![frames] },
            });
        }
    }
    r.normalise();
    Ok(r)
}
