//! `warplight step` in a real pseudo-terminal: the binary runs inside a
//! detached tmux session of 80×24; keys go in with `send-keys`, the screen
//! comes back with `capture-pane`. Needs tmux (`.ci/run` installs it); skips
//! without it unless WARPLIGHT_REQUIRE_EXTERNAL=1 (see `common::external`).

mod common;

use std::process::Command;
use std::time::{Duration, Instant};

struct Tmux {
    socket: String,
}

impl Tmux {
    fn start(cmd: &str) -> Option<Tmux> {
        common::external("tmux", "apt-get install tmux")?;
        let socket = format!("warplight-test-{}", std::process::id());
        let ok = Command::new("tmux")
            .args(["-L", &socket, "new-session", "-d", "-s", "w", "-x", "80", "-y", "24", cmd])
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .status()
            .unwrap_or_else(|e| panic!("tmux did not run: {e}"));
        assert!(ok.success(), "tmux could not start");
        Some(Tmux { socket })
    }

    fn keys(&self, keys: &[&str]) {
        let ok = Command::new("tmux").args(["-L", &self.socket, "send-keys", "-t", "w"]).args(keys).status().unwrap();
        assert!(ok.success());
    }

    fn screen(&self) -> String {
        let o = Command::new("tmux").args(["-L", &self.socket, "capture-pane", "-p", "-t", "w"]).output().unwrap();
        String::from_utf8_lossy(&o.stdout).into_owned()
    }

    /// Waits until the screen contains `text`.
    fn wait_for(&self, text: &str) -> String {
        let start = Instant::now();
        loop {
            let s = self.screen();
            if s.contains(text) {
                return s;
            }
            assert!(start.elapsed() < Duration::from_secs(30), "the screen never showed {text:?}:\n{s}");
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    fn alive(&self) -> bool {
        Command::new("tmux")
            .args(["-L", &self.socket, "has-session", "-t", "w"])
            .output()
            .is_ok_and(|o| o.status.success())
    }
}

impl Drop for Tmux {
    fn drop(&mut self) {
        let _ = Command::new("tmux").args(["-L", &self.socket, "kill-server"]).output();
    }
}

#[test]
fn step_view_in_a_pseudo_terminal() {
    let bin = env!("CARGO_BIN_EXE_warplight");
    // `; sleep` keeps the pane open after a crash so that its message can be read
    let Some(t) = Tmux::start(&format!("{bin} step examples/if_else.toml --device gt200 || sleep 30")) else { return };
    let s = t.wait_for("step 0");
    assert!(s.contains("divergence.cu") && s.contains("PTX 24: mov.u32") && s.contains("gt200"), "{s}");
    assert!(s.contains("################################ active ffffffff (32)"), "{s}");
    assert!(s.lines().count() <= 24 && s.lines().all(|l| l.chars().count() <= 80), "fits 80x24:\n{s}");
    for _ in 0..12 {
        t.keys(&["s"]);
    }
    let s = t.wait_for("step 12 ");
    assert!(s.contains(".#.#.#.#.#.#.#.#.#.#.#.#.#.#.#.# active aaaaaaaa (16)"), "{s}");
    assert!(s.contains("diverged"), "{s}");
    // step back; run to the even side's store (PTX line 55), step over it and
    // look at the memory panel: 16 lanes, stride 2 words
    t.keys(&["u"]);
    t.wait_for("step 11 ");
    t.keys(&["g", "5", "5", "Enter"]);
    t.wait_for("PTX 55: st.global.u32");
    // v shows the PTX pane instead of the source
    t.keys(&["v"]);
    t.wait_for(">  55 st.global.u32");
    t.keys(&["s", "3"]);
    let s = t.wait_for("global store");
    assert!(s.contains("global store 4B x16: gt200 2 transactions, 128 B moved for 64 B used"), "{s}");
    t.keys(&["?"]);
    let s = t.wait_for("keys (any key closes)");
    assert!(s.contains("Lanes: # running"), "the help fits 80x24:\n{s}");
    t.keys(&["Enter"]);
    t.keys(&["q"]);
    let start = Instant::now();
    while t.alive() {
        assert!(start.elapsed() < Duration::from_secs(10), "q did not quit:\n{}", t.screen());
        std::thread::sleep(Duration::from_millis(50));
    }
}
