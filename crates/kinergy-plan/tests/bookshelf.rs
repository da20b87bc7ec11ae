//! The bookshelf example (Kallmann 2005, Fig. 5) end to end.

use std::path::PathBuf;

use kinergy_plan::scene::Scene;
use kinergy_plan::task::{Planner, TaskSettings};
use nalgebra::Point3;

fn scene() -> Scene {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/bookshelf/scene.json");
    Scene::read(&path).unwrap()
}

#[test]
fn relocates_the_blue_book() {
    let scene = scene();
    assert!(scene.triangle_count() > 11_000);
    for seed in 0..5 {
        let mut settings = TaskSettings::default();
        settings.rrt.seed = seed;
        let planner = Planner::new(scene.clone(), settings).unwrap();
        let t = std::time::Instant::now();
        let m = planner.relocate("blue_book", &Point3::new(-0.22, 1.49, 0.50));
        let m = match m {
            Ok(m) => m,
            Err(e) => panic!("seed {seed}: {e}"),
        };
        eprintln!(
            "seed {seed}: {:.1} ms, {} frames",
            t.elapsed().as_secs_f64() * 1e3,
            m.poses.len()
        );
        for p in &m.phases {
            if let Some(pl) = &p.planned {
                eprintln!(
                    "  {}: {} iterations, {} nodes, {:.2} ms; smoothing {:.3} -> {:.3} m in {:.2} ms ({} raw configs)",
                    p.name,
                    pl.search.iterations,
                    pl.search.nodes,
                    pl.search.seconds * 1e3,
                    pl.smoothing.length_before,
                    pl.smoothing.length_after,
                    pl.smoothing.seconds * 1e3,
                    pl.raw.configs.len()
                );
            }
        }
    }
}
