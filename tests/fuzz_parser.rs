//! The PTX front end never panics: random token soups and byte-level mutations
//! of real kernels either load or give an error with a position.
//! (`fuzz/` holds the same check as a cargo-fuzz target for long runs.)

#![allow(clippy::needless_range_loop)]

use proptest::prelude::*;

const WORDS: &[&str] = &[
    ".version 7.8",
    ".target sm_90",
    ".address_size 64",
    ".visible",
    ".entry",
    ".func",
    ".reg",
    ".b32",
    ".pred",
    ".param",
    ".u64",
    ".shared",
    ".local",
    ".global",
    ".const",
    ".align 8",
    "%r<4>",
    "%r1",
    "%rd1",
    "%p1",
    "k",
    "(",
    ")",
    "{",
    "}",
    "[",
    "]",
    ";",
    ",",
    "@",
    "!",
    "ld.global.u32",
    "st.shared.f32",
    "add.s32",
    "bra",
    "L1:",
    "L1",
    "setp.lt.s32",
    "0f3F800000",
    "-1",
    "42",
    "ret;",
    "call.uni",
    "mov.u32",
    "%tid.x",
    "=",
    "|",
    "+",
    "-4",
    ".loc 1 2 3",
];

fn real_ptx() -> Vec<String> {
    let mut v = Vec::new();
    for f in ["divergence", "atomics", "calls", "shared"] {
        for ext in ["ptx", "nvcc.ptx"] {
            v.push(std::fs::read_to_string(format!("kernels/tests/{f}.{ext}")).unwrap());
        }
    }
    v
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn token_soup_never_panics(words in prop::collection::vec(0..WORDS.len(), 0..80)) {
        let src: Vec<&str> = words.iter().map(|&i| WORDS[i]).collect();
        let _ = warplight::ptx::load(&src.join(" "), "soup.ptx");
    }

    #[test]
    fn mutated_kernels_never_panic(file in 0usize..8, edits in prop::collection::vec((any::<u32>(), any::<u8>(), 0u8..3), 1..6)) {
        let mut bytes = real_ptx()[file].clone().into_bytes();
        for (pos, byte, kind) in edits {
            if bytes.is_empty() { break; }
            let p = pos as usize % bytes.len();
            match kind {
                0 => { bytes.remove(p); }
                1 => bytes.insert(p, byte),
                _ => bytes[p] = byte,
            }
        }
        let src = String::from_utf8_lossy(&bytes);
        if let Err(e) = warplight::ptx::load(&src, "mutated.ptx") {
            // The position is inside the text and the message names the file.
            prop_assert!(e.pos.line as usize <= src.lines().count() + 1, "{}", e);
            prop_assert!(e.to_string().starts_with("mutated.ptx:"));
        }
    }
}
