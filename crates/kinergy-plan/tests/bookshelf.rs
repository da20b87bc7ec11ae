//! The bookshelf example (Kallmann 2005, Fig. 5): its files are what the code makes, and the
//! relocation succeeds for many seeds.

use std::path::PathBuf;

use kinergy_plan::obj::{parse_obj, write_obj};
use kinergy_plan::scene::Scene;
use kinergy_plan::shelf::{OBJ_HEADER, ShelfUnit};
use kinergy_plan::task::{Planner, TaskSettings};
use nalgebra::Point3;

fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/bookshelf")
        .join(name)
}

#[test]
fn the_committed_shelf_is_what_the_generator_writes() {
    let committed = std::fs::read_to_string(example("shelf.obj")).unwrap();
    let mesh = ShelfUnit::default().mesh();
    assert_eq!(committed, write_obj(&mesh, &OBJ_HEADER));
    let parsed = parse_obj(&committed, &example("shelf.obj")).unwrap();
    assert_eq!(parsed.triangle_count(), 11_900);
}

#[test]
fn relocates_the_blue_book_for_many_seeds() {
    let scene = Scene::read(&example("scene.json")).unwrap();
    assert_eq!(scene.triangle_count(), 11_900);
    let to = Point3::new(-0.22, 1.49, 0.50);
    for seed in 0..20 {
        let mut settings = TaskSettings::default();
        settings.rrt.seed = seed;
        let planner = Planner::new(scene.clone(), settings).unwrap();
        let m = planner
            .relocate("blue_book", &to)
            .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let end = m.objects[0].poses.last().unwrap();
        assert!((end.translation.vector - to.coords).norm() < 1e-9);
    }
}
