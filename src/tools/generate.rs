//! `raystep generate spheres`: scenes of many spheres, to see how the cost grows
//! with the scene. The spheres are made in `src/io/generated.rs`; this writes
//! the scene file.
//!
//! A scene file lists its spheres up to [`MAX_LISTED`]; a larger one holds the
//! recipe instead, a `[generate]` section (`spheres = N`, `seed = S`) that the
//! scene loader turns into the same spheres with [`objects`]. A list of a million
//! spheres would be a 165 MB file, which the TOML reader would take seconds and
//! gigabytes to read.

use std::fmt::Write;

pub use crate::io::generated::{spheres, Ball, MAX_GENERATED};
pub use crate::io::scene_file::generated_objects as objects;
use crate::scene::Scene;

/// The most spheres a generated scene file lists one by one (a 16.7 MB file, near the
/// 16 MiB a scene file may be; the loader reads it in parts, as the TOML reader
/// alone would take 0.8 s and 531 MB); above, it holds the recipe.
pub const MAX_LISTED: usize = 100_000;

/// The camera, light and floor of every generated scene, with the comment that
/// names the command.
fn header(count: usize, seed: u64) -> String {
    format!(
        "# {count} spheres over the floor: raystep generate spheres --count {count} --seed {seed}\n\
         \n[image]\nwidth = 1920\nheight = 1080\n\n[camera]\nposition = [0, 0.2, 1]\n\n\
         [light]\nposition = [5, 5, 5]\n\n[render]\nmax_depth = 3\n\n\
         [[plane]]\nsphere = {{ center = [0, -9000, 0], radius = 8999.3 }}\n\
         ambient = [0.1, 0.1, 0.1]\ndiffuse = [0.6, 0.6, 0.6]\n"
    )
}

/// The scene file of N spheres from `seed`, at 1920 × 1080, each sphere listed.
pub fn spheres_toml(count: usize, seed: u64) -> String {
    let mut text = String::with_capacity(200 + count * 120);
    text.push_str(&header(count, seed));
    for b in spheres(count, seed) {
        let [x, y, z] = b.center;
        let [ar, ag, ab] = b.ambient;
        let [dr, dg, db] = b.diffuse;
        let _ = writeln!(
            text,
            "[[sphere]]\ncenter = [{x}, {y}, {z}]\nradius = {}\nambient = [{ar}, {ag}, {ab}]\n\
             diffuse = [{dr}, {dg}, {db}]\nreflection = {}",
            b.radius, b.reflection
        );
    }
    text
}

/// The same scene as [`spheres_toml`], as its recipe: the header and a
/// `[generate]` section, whatever the count.
pub fn recipe_toml(count: usize, seed: u64) -> String {
    format!(
        "{}\n# The spheres are not listed: the loader makes them from this recipe, as\n\
         # `raystep generate spheres` would list them (it lists up to {MAX_LISTED}).\n\
         [generate]\nspheres = {count}\nseed = {seed}\n",
        header(count, seed)
    )
}

/// The scene of [`spheres_toml`], built directly, at any count (`chart --scale`
/// goes past the [`MAX_GENERATED`] a scene file's recipe may ask for).
pub fn scene(count: usize, seed: u64) -> Scene {
    let mut scene = crate::io::scene_file::parse(&spheres_toml(0, seed), "generated")
        .expect("the generated header is a valid scene");
    let floor = scene.objects.pop().expect("the header has the floor");
    scene.objects = objects(count, seed).collect();
    scene.objects.push(floor);
    scene
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scene_file_and_the_scene_built_directly_agree() {
        let text = spheres_toml(200, 3);
        let parsed = crate::io::scene_file::parse(&text, "generated").unwrap();
        assert_eq!(parsed, scene(200, 3));
    }

    #[test]
    fn the_recipe_makes_the_spheres_the_list_lists() {
        let listed = crate::io::scene_file::parse(&spheres_toml(300, 11), "list").unwrap();
        let made = crate::io::scene_file::parse(&recipe_toml(300, 11), "recipe").unwrap();
        assert_eq!(made.objects.len(), 301);
        assert_eq!(made, listed);
        assert_ne!(made, scene(300, 12));
    }
}
