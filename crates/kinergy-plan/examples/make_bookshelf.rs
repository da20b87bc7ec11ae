//! Writes the bookshelf example's shelf mesh: `cargo run -p kinergy-plan --example
//! make_bookshelf -- examples/bookshelf/shelf.obj`. A test checks the committed file is what
//! this writes.

use kinergy_plan::obj::write_obj;
use kinergy_plan::shelf::ShelfUnit;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .ok_or("usage: make_bookshelf OUT.obj")?;
    let unit = ShelfUnit::default();
    unit.validate()?;
    let text = write_obj(&unit.mesh(), &kinergy_plan::shelf::OBJ_HEADER);
    std::fs::write(&path, text)?;
    Ok(())
}
