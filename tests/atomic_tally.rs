//! The atomics' tally by address (`model::atomic_tally`) on a launched
//! kernel, attached to every launch of a device (`Device::set_observer`) or
//! to one (`Device::launch_observed`, which takes precedence), and silent
//! below fidelity `memory`.

use std::sync::Arc;

use warplight::model::atomic_tally::{AtomicSharing, AtomicTally};
use warplight::sim::{Arg, Device, Fidelity, LaunchConfig, SimConfig};

/// Each thread adds 1 to word `tid % 4` of `p`: every warp's 32 lanes on 4
/// addresses, every address updated by every warp.
const FOUR_WORDS: &str = ".version 7.0\n.target sm_70\n.address_size 64\n\
.visible .entry four(.param .u64 p)\n{\n .reg .b32 %r<3>;\n .reg .b64 %rd<4>;\n\
 ld.param.u64 %rd1, [p];\n mov.u32 %r1, %tid.x;\n and.b32 %r2, %r1, 3;\n\
 mul.wide.u32 %rd2, %r2, 4;\n add.s64 %rd3, %rd1, %rd2;\n red.global.add.u32 [%rd3], 1;\n ret;\n}\n";

fn device(fidelity: Fidelity) -> Device {
    Device::with_config(SimConfig { threads: 2, fidelity, ..SimConfig::default() })
}

/// Two CTAs of 64 threads (4 warps) on `dev`: the words' sum after.
fn run(dev: &mut Device, observer: Option<&AtomicTally>) -> u32 {
    let m = dev.load_ptx(FOUR_WORDS, "four.ptx").expect("load");
    let p = dev.alloc_zeroed::<u32>(4);
    let args = [Arg::Ptr(p)];
    match observer {
        Some(o) => dev.launch_observed(&m, "four", LaunchConfig::linear(2, 64), &args, Some(o)),
        None => dev.launch(&m, "four", LaunchConfig::linear(2, 64), &args),
    }
    .expect("launch");
    dev.read::<u32>(p, 4).iter().sum()
}

const FOUR_WARPS: AtomicSharing = AtomicSharing {
    instructions: 4,
    lane_updates: 128,
    addresses: 4,
    same_instruction_repeats: 4 * 28,
    shared_addresses: 4,
    shared_lane_updates: 128,
    max_per_address: 32,
};

#[test]
fn the_devices_observer_tallies_its_launches() {
    let mut dev = device(Fidelity::Memory);
    let tally = Arc::new(AtomicTally::new());
    dev.set_observer(Some(tally.clone()));
    assert_eq!(run(&mut dev, None), 128);
    assert_eq!(tally.sharing(), FOUR_WARPS);
    // a launch given its own observer leaves the device's alone
    let own = AtomicTally::new();
    run(&mut dev, Some(&own));
    assert_eq!(own.sharing(), FOUR_WARPS);
    assert_eq!(tally.sharing(), FOUR_WARPS);
    // cleared: the next launch is not tallied
    dev.set_observer(None);
    run(&mut dev, None);
    assert_eq!(tally.sharing(), FOUR_WARPS);
}

#[test]
fn below_memory_fidelity_nothing_is_tallied() {
    let mut dev = device(Fidelity::Functional);
    let tally = Arc::new(AtomicTally::new());
    dev.set_observer(Some(tally.clone()));
    assert_eq!(run(&mut dev, None), 128);
    assert_eq!(tally.sharing(), AtomicSharing::default());
}
