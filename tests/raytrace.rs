//! The ray-tracing kernels on the emulator agree with the native reference
//! caster: the same primary hit triangle for every pixel, the same colours,
//! and (stack-based) the same traversal work, ray for ray. The work the
//! emulator reads off its per-line counters equals what the instrumented
//! build tallies in the kernel.

use std::path::Path;

use warplight::host::kdtree::{BuildParams, Heuristic, KdTree, build};
use warplight::host::raycast::{Caster, TraceStats, render};
use warplight::host::rt_kernels::{self, Build, Variant};
use warplight::host::scene::Scene;
use warplight::host::scene_file;
use warplight::model::Profile;
use warplight::sim::Device;

fn setup(name: &str, res: u32) -> (Scene, KdTree, warplight::host::camera::Camera) {
    let scene = scene_file::load(Path::new(&format!("scenes/{name}.toml"))).unwrap();
    let tris: Vec<[glam::Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Siroh));
    let mut cam = scene.flight.camera(&scene.camera, 0);
    cam.resolution = [res, res];
    (scene, tree, cam)
}

#[test]
fn every_variant_matches_the_native_caster() {
    for name in ["scene6", "cornell-box", "ring"] {
        let (scene, tree, cam) = setup(name, 24);
        let caster = Caster::new(&scene, &tree);
        let (native, nst) = render(&caster, &cam, glam::Vec3::ZERO);
        let native_hits: Vec<i32> = (0..24 * 24)
            .map(|i| {
                let r = cam.ray(i % 24, i / 24);
                let mut st = TraceStats::default();
                caster.intersect(&r, caster.eps(), f32::INFINITY, false, &mut st).map_or(-1, |h| h.tri as i32)
            })
            .collect();
        let mut dev = Device::new();
        let module = rt_kernels::load(&mut dev).unwrap();
        let mut stack_local = 0;
        // the traversal variants, and the cache variants that keep the native traversal
        for v in
            Variant::ALL.into_iter().chain([Variant::NodeCache1, Variant::StackCache1, Variant::NodeCache1StackCache1])
        {
            let k = rt_kernels::render(&mut dev, &module, &scene, &tree, &cam, glam::Vec3::ZERO, v, Profile::Gt200)
                .unwrap();
            assert_eq!(k.hit_tri, native_hits, "{name} {v:?}: primary hits");
            for (i, (a, b)) in k.image.pixels.iter().zip(&native.pixels).enumerate() {
                for c in 0..3 {
                    assert!(
                        (a[c] - b[c]).abs() <= 1e-6 * b[c].abs().max(1.0),
                        "{name} {v:?} pixel {i}: {a:?} vs {b:?}"
                    );
                }
            }
            assert_eq!(k.trace.rays, nst.rays, "{name} {v:?}: the same rays");
            assert_eq!(
                (k.trace.primary, k.trace.shadow, k.trace.reflection),
                (nst.primary, nst.shadow, nst.reflection),
                "{name} {v:?}: the same kinds of rays"
            );
            if matches!(v, Variant::Stack | Variant::NodeCache1 | Variant::StackCache1 | Variant::NodeCache1StackCache1)
            {
                assert_eq!(k.trace.inner_nodes, nst.inner_nodes, "{name} {v:?}: the same traversal");
                assert_eq!(k.trace.plane_tests, nst.plane_tests);
                assert_eq!(k.trace.barycentric_tests, nst.barycentric_tests);
                // every push counts, whether it went to local memory or (stack cache I)
                // into the register head: the same pushes as the native traversal
                assert_eq!(k.trace.pushes, nst.pushes, "{name} {v:?}: the same pushes");
                let local = k.trace.local_stack_accesses;
                if matches!(v, Variant::Stack | Variant::NodeCache1) {
                    // every push and every pop of a pushed entry goes to local memory
                    assert!((nst.pushes..=2 * nst.pushes).contains(&local), "{name} {v:?}: {local} local accesses");
                    stack_local = local;
                } else {
                    assert!(local < stack_local, "{name} {v:?}: the register head keeps accesses out of local memory");
                }
            } else {
                assert!(k.trace.inner_nodes >= nst.inner_nodes, "{name} {v:?}: restarts only add node visits");
            }
            assert!(k.launch.totals.atomics.global > 0, "the job queue hands out pixel blocks");
        }
    }
}

#[test]
fn tables_4_5_and_4_7_on_a_small_flight() {
    use warplight::repro::fabianowski2011::flight::measure;
    let scene = scene_file::load(Path::new("scenes/scene6.toml")).unwrap();
    let mut ticks = 0;
    let r = measure(&scene, 2, 16, &Variant::ALL, |_, _| ticks += 1).unwrap();
    assert_eq!(ticks, 2 * 5);
    let inner = r.inner_per_ray();
    let (stack, stackless, pushdown, short, both) = (inner[0], inner[1], inner[2], inner[3], inner[4]);
    // restarts add node visits; push-down saves some of them; a short stack almost all
    assert!(stackless > pushdown && pushdown > stack, "{inner:?}");
    assert!(short >= stack && short < stack * 1.1 && both <= short, "{inner:?}");
    assert!(r.instr_per_ray().iter().all(|&x| x > 100.0));
}

#[test]
fn table_4_3_counts_with_three_trees() {
    use warplight::repro::fabianowski2011::{HEURISTIC_COUNTS, table_4_3};
    use warplight::repro::protocol::Protocol;
    use warplight::repro::registry::{Workspace, resolve};
    use warplight::repro::results::{Results, SceneInfo};
    let scene = scene_file::load(Path::new("scenes/scene6.toml")).unwrap();
    let mut ws = Workspace::new(&scene, 0..1, 24);
    let samples = table_4_3::measure(&mut ws, &mut |_| {}).unwrap();
    let mut r = Results::new(
        "test",
        Protocol::quick().with(Some(1), Some(24)),
        vec!["fabianowski:4.3".into()],
        vec![HEURISTIC_COUNTS.into()],
    );
    r.scenes.push(SceneInfo {
        name: "scene6".into(),
        triangles: scene.triangles.len(),
        thesis_triangles: None,
        flight_frames: 50,
        frames: vec![],
    });
    r.samples = samples;
    // the same rays with every tree; every count positive
    let rays: Vec<f64> =
        ["sah", "numerical", "siroh"].iter().map(|v| r.sum(HEURISTIC_COUNTS, "scene6", v, "rays").unwrap()).collect();
    assert!(rays[0] == rays[1] && rays[1] == rays[2] && rays[0] > 0.0, "{rays:?}");
    let p = table_4_3::per_ray(&r, "scene6").unwrap();
    assert!(p.iter().flatten().all(|&x| x > 0.0), "{p:?}");
    // every compared cell of the scene's row has a verdict (the verdicts
    // themselves: tests/repro.rs, against the committed baseline)
    let e = resolve(&["fabianowski:4.3".into()]).unwrap()[0];
    let t = &table_4_3::render(&e, &r)[0];
    let row = t.rows.iter().find(|r| r.label == "scene6").unwrap();
    let compared = t.columns.iter().filter(|c| c.tolerance.is_some()).count();
    assert_eq!(row.cells.iter().filter(|c| c.verdict.is_some()).count(), compared, "{}", t.markdown());
}

/// Fig. 4.3's failure cases of restart-based traversal: zero-volume nodes
/// (planar triangles shaved off by the SAH), coplanar triangles, rays running
/// inside split planes and rays starting on them. Every variant must find what
/// the stack-based native caster finds.
#[test]
fn stackless_variants_survive_degenerate_geometry() {
    use glam::Vec3;
    use warplight::host::scene::{Light, Material, Triangle};
    let v = Vec3::new;
    let mut tris = Vec::new();
    let quad = |tris: &mut Vec<Triangle>, a: Vec3, b: Vec3, d: Vec3, m: u32| {
        let c = b + d - a;
        tris.push(Triangle { v: [a, b, c], material: m });
        tris.push(Triangle { v: [a, c, d], material: m });
    };
    // a planar floor at y = 0 split into many cells (zero-volume nodes)
    for i in 0..6 {
        for j in 0..6 {
            let (x, z) = (i as f32 - 3.0, j as f32 - 3.0);
            quad(&mut tris, v(x, 0.0, z), v(x + 1.0, 0.0, z), v(x, 0.0, z + 1.0), 0);
        }
    }
    // coplanar walls at x = 2 (three identical copies) and at x = -2
    for _ in 0..3 {
        quad(&mut tris, v(2.0, -1.0, -3.0), v(2.0, -1.0, 3.0), v(2.0, 2.0, -3.0), 1);
    }
    quad(&mut tris, v(-2.0, -1.0, -3.0), v(-2.0, 2.0, -3.0), v(-2.0, -1.0, 3.0), 1);
    // thin slabs touching the floor plane and each other at x = 0.5
    quad(&mut tris, v(0.5, 0.0, -1.0), v(0.5, 1.0, -1.0), v(0.5, 0.0, 1.0), 0);
    quad(&mut tris, v(0.5, 0.0, -0.5), v(1.0, 0.0, -0.5), v(0.5, 1.0, -0.5), 0);
    let mats = vec![Material::diffuse("a", [0.8, 0.8, 0.8]), Material::diffuse("b", [0.2, 0.6, 0.9])];
    let mut scene = Scene::assemble("degenerate", Path::new("degenerate"), tris, mats);
    scene.lights.push(Light::Point { position: [0.0, 1.5, 0.0], intensity: [2.0, 2.0, 2.0] });
    let tris: Vec<[Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let caster_tree = build(&tris, BuildParams::thesis(Heuristic::Sah));
    // cameras: inside the floor plane (the middle row of an odd image runs along y = 0),
    // on the split plane x = 0.5, and looking down across the coplanar walls
    let cams = [
        ([-2.5, 0.0, 0.2], [1.0, 0.0, 0.0]),
        ([0.5, 0.5, -2.0], [0.0, 0.0, 1.0]),
        ([-1.0, 1.5, 0.3], [1.0, -0.6, 0.05]),
    ];
    let caster = Caster::new(&scene, &caster_tree);
    let mut dev = Device::new();
    let module = rt_kernels::load(&mut dev).unwrap();
    for (pos, dir) in cams {
        let cam = warplight::host::camera::Camera {
            position: pos,
            direction: dir,
            up: [0.0, 1.0, 0.0],
            fov_y: 70.0,
            resolution: [25, 25],
        };
        let native: Vec<i32> = (0..25 * 25)
            .map(|i| {
                let r = cam.ray(i % 25, i / 25);
                let mut st = TraceStats::default();
                caster.intersect(&r, caster.eps(), f32::INFINITY, false, &mut st).map_or(-1, |h| h.tri as i32)
            })
            .collect();
        assert!(native.iter().filter(|&&h| h >= 0).count() > 100, "the views see the geometry");
        for var in Variant::EVERY {
            let k = rt_kernels::render(&mut dev, &module, &scene, &caster_tree, &cam, Vec3::ZERO, var, Profile::Gt200)
                .unwrap();
            // coplanar duplicates may tie: compare the hit distance where triangles differ
            for (i, (&a, &b)) in k.hit_tri.iter().zip(&native).enumerate() {
                if a != b {
                    let same_plane = a >= 0 && b >= 0 && {
                        let (ta, tb) = (&scene.triangles[a as usize].v, &scene.triangles[b as usize].v);
                        ta.iter().zip(tb).all(|(p, q)| (*p - *q).length() < 1e-6)
                    };
                    assert!(same_plane, "{var:?} camera {pos:?} pixel {i}: kernel hit {a}, native {b}");
                }
            }
        }
    }
}

#[test]
fn caches_cut_texture_fetches_and_local_stack_accesses() {
    use warplight::repro::fabianowski2011::flight::measure;
    let scene = scene_file::load(Path::new("scenes/sponza.toml")).unwrap();
    let r = measure(&scene, 1, 16, &Variant::CACHES, |_, _| {}).unwrap();
    let tex = r.per_ray(|t| t.tex_node_fetches);
    let local = r.per_ray(|t| t.local_stack_accesses);
    let inner = r.inner_per_ray();
    // baseline: every inner node is one texture fetch (Table 4.8 (a) column 1 = Table 4.5's n_T)
    assert!((tex[0] - inner[0]).abs() < 1e-9);
    // columns: 1 baseline, 2 NC I, 3 SC I, 4 SC III, 5 NC I + SC I, 6 NC II + SC II, 7 NC I + SC III
    // node cache I serves the top 10 levels; stack cache I leaves texture fetches alone
    assert!(tex[1] < 0.8 * tex[0] && (tex[2] - tex[0]).abs() < 1e-9 && (tex[4] - tex[1]).abs() < 1e-9, "{tex:?}");
    // stack cache I keeps the top entry in registers; node caches leave the stack alone
    assert!(
        local[2] < 0.8 * local[0] && (local[1] - local[0]).abs() < 1e-9 && (local[4] - local[2]).abs() < 1e-9,
        "{local:?}"
    );
    // node cache II + stack cache II: fewer of both than the baseline
    assert!(tex[5] < tex[0] && local[5] < local[0], "{tex:?} {local:?}");
    // speculation (stack cache III) traverses at least as many nodes; node cache I then serves most
    assert!(tex[3] >= tex[0] && tex[6] < tex[3], "{tex:?}");
}

#[test]
fn emulated_renders_match_the_reference_images() {
    use warplight::host::image::FrameBuffer;
    for name in ["scene6", "cornell-box"] {
        let scene = scene_file::load(Path::new(&format!("scenes/{name}.toml"))).unwrap();
        let tris: Vec<[glam::Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
        // the reference images were rendered with SAH trees by the native caster
        let tree = build(&tris, BuildParams::thesis(Heuristic::Sah));
        let mut cam = scene.flight.camera(&scene.camera, 0);
        cam.resolution = [96, 96];
        let mut dev = Device::new();
        let module = rt_kernels::load(&mut dev).unwrap();
        let k = rt_kernels::render(
            &mut dev,
            &module,
            &scene,
            &tree,
            &cam,
            glam::Vec3::ZERO,
            Variant::Stackless,
            Profile::Gt200,
        )
        .unwrap();
        let want = FrameBuffer::read_png(Path::new(&format!("reference_images/{name}.png"))).unwrap().to_srgb8(0.0);
        let got = k.image.to_srgb8(0.0);
        let worst = got.iter().zip(&want).map(|(a, b)| (*a as i32 - *b as i32).abs()).max().unwrap();
        assert!(worst <= 1, "{name}: the emulated render differs by {worst} steps");
    }
}

/// Item by item, the counts the emulator reads off the `@count` lines of the
/// plain build equal the instrumented build's in-kernel tallies, for every
/// variant; the plain build stores no tallies (the instrumented one writes them per pixel).
#[test]
fn emulator_counts_equal_the_instrumented_tallies() {
    let mut dev = Device::new();
    let plain = rt_kernels::load_build(&mut dev, Build::Plain).unwrap();
    let inst = rt_kernels::load_build(&mut dev, Build::Instrumented).unwrap();
    for (name, variants) in [
        ("scene6", &Variant::EVERY[..]),
        ("sponza", &Variant::CACHES[..]),
        ("sibenik", &[Variant::Stack, Variant::PushDownShortStack][..]),
    ] {
        let (scene, tree, cam) = setup(name, 12);
        for &v in variants {
            let mut run = |m, b| {
                rt_kernels::render_build(&mut dev, m, b, &scene, &tree, &cam, glam::Vec3::ZERO, v, Profile::Gt200)
                    .unwrap()
            };
            let (a, b) = (run(&plain, Build::Plain), run(&inst, Build::Instrumented));
            assert_eq!(a.trace, b.trace, "{name} {v:?}: emulator counts vs in-kernel tallies");
            assert_eq!(a.hit_tri, b.hit_tri, "{name} {v:?}");
            assert!(a.trace.inner_nodes > 0 && a.trace.leaves > 0 && a.trace.plane_tests > 0, "{name} {v:?}");
            // the tallies' stores to the stats buffer: the plain build makes none (its
            // instruction count need not be lower: clang schedules the two builds apart)
            assert!(
                a.launch.totals.stores.global < b.launch.totals.stores.global,
                "{name} {v:?}: the plain build stores no tallies"
            );
        }
    }
}

/// Every `@count` tag of the kernel source names an opcode that the PTX
/// places on the tagged line: a recompiled kernel cannot silently count nothing.
#[test]
fn every_count_tag_has_its_instruction_in_the_ptx() {
    let tags = rt_kernels::count_tags(rt_kernels::SOURCE);
    let names: std::collections::BTreeSet<&str> = tags.iter().map(|t| t.name.as_str()).collect();
    for n in [
        "rays",
        "inner",
        "leaves",
        "planes",
        "barys",
        "push",
        "spill",
        "regpush",
        "pop",
        "cached_node",
        "shadow",
        "reflection",
        "texels",
    ] {
        assert!(names.contains(n), "no @count tag for {n}: {names:?}");
    }
    let mut dev = Device::new();
    let m = rt_kernels::load(&mut dev).unwrap();
    let file = m.prog.files.iter().position(|f| f.ends_with("fabianowski2011/raytrace.cu")).unwrap() as u32;
    for t in &tags {
        let found = m
            .prog
            .functions
            .iter()
            .flat_map(|f| &f.info)
            .any(|i| i.src.is_some_and(|s| s.file == file && s.line == t.line) && i.opcode == t.opcode);
        assert!(found, "raytrace.cu:{}: no {} for @count {}", t.line, t.opcode, t.name);
    }
}

/// Sponza and Sibenik with their MTL materials: the kernels fetch a texel of
/// the texture map at every shaded hit on a textured material and trace a
/// reflection ray at every hit on a specular one (Sibenik's glass and floor),
/// exactly as the native caster does: the same hits,
/// colours, rays of each kind and texel fetches.
#[test]
fn textured_scenes_match_the_native_caster() {
    let mut dev = Device::new();
    let module = rt_kernels::load(&mut dev).unwrap();
    for (name, frame) in [("sponza", 0), ("sibenik", 0)] {
        let (scene, tree, _) = setup(name, 20);
        let mut cam = scene.flight.camera(&scene.camera, frame);
        cam.resolution = [20, 20];
        assert!(!scene.textures.is_empty() && scene.uvs.len() == scene.triangles.len(), "{name}: textures loaded");
        let caster = Caster::new(&scene, &tree);
        let (native, nst) = render(&caster, &cam, glam::Vec3::ZERO);
        assert!(nst.texel_fetches > 0, "{name}: textured surfaces are seen");
        for v in [Variant::Stack, Variant::Stackless] {
            let k = rt_kernels::render(&mut dev, &module, &scene, &tree, &cam, glam::Vec3::ZERO, v, Profile::Gt200)
                .unwrap();
            for (i, (a, b)) in k.image.pixels.iter().zip(&native.pixels).enumerate() {
                for c in 0..3 {
                    assert!(
                        (a[c] - b[c]).abs() <= 1e-6 * b[c].abs().max(1.0),
                        "{name} {v:?} pixel {i}: {a:?} vs {b:?}"
                    );
                }
            }
            assert_eq!(
                (k.trace.rays, k.trace.shadow, k.trace.reflection, k.trace.texel_fetches),
                (nst.rays, nst.shadow, nst.reflection, nst.texel_fetches),
                "{name} {v:?}: rays, shadow rays, reflection rays, texel fetches"
            );
        }
        // without its texture maps the scene renders other colours
        let mut plain = scene.clone();
        plain.surfaces.iter_mut().for_each(|s| s.texture = None);
        let (untextured, _) = render(&Caster::new(&plain, &tree), &cam, glam::Vec3::ZERO);
        assert_ne!(untextured.pixels, native.pixels, "{name}: the texture maps change the image");
    }
    // Sibenik's floor and glass reflect (the thesis: "Glass surfaces and the floor blend a specular and a
    // diffuse BRDF"); a texel is the texture's colour at (u, v), v = 0 the bottom row, repeated
    let (scene, tree, cam) = setup("sibenik", 20);
    let (_, st) = render(&Caster::new(&scene, &tree), &cam, glam::Vec3::ZERO);
    assert!(st.reflection > 0, "sibenik: the floor reflects");
    let t = &scene.textures[0];
    let (w, h) = (t.width, t.height);
    assert_eq!(warplight::host::scene::Texture::index(w, h, 0.0, 0.999), 0);
    assert_eq!(warplight::host::scene::Texture::index(w, h, 0.0, 0.001), ((h - 1) * w) as usize);
    assert_eq!(warplight::host::scene::Texture::index(w, h, 1.25, 1.999), (w / 4) as usize);
    assert_eq!(warplight::host::scene::Texture::index(w, h, -0.001, 0.999), (w - 1) as usize);
}

#[test]
fn scene_info_lists_sibeniks_textures_and_reflection_weights() {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_warplight"))
        .args(["scene", "info", "sibenik"])
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{out}{}", String::from_utf8_lossy(&o.stderr));
    let line = |name: &str| {
        out.lines().find(|l| l.split_whitespace().next() == Some(name)).unwrap_or_else(|| panic!("{name}: {out}"))
    };
    // the MTL's illum-4 glass reflects with its Ks; the marble floor with the scene file's weight, textured
    assert!(line("staklo").ends_with("1687 triangles  reflect [0.784, 0.784, 0.784]"), "{out}");
    assert!(
        line("pod").ends_with("251 triangles  texture textures/mramor6x6.png  reflect [0.25, 0.25, 0.25]"),
        "{out}"
    );
    assert!(!line("pod_tepih").contains("reflect") && !line("pod_tepih").contains("texture"), "{out}");
    assert!(out.contains("materials  16 (8 textured, 6 reflecting"), "{out}");
    assert!(out.contains("textures   3 (2.6 MB of 32-bit texels)"), "{out}");
    assert!(line("textures/KAMEN-stup.png").contains("512 x 256 "), "{out}");
}
