//! What the benchmark examples share: a shipped scene's set-up without contact, whose `K` is
//! the linear floor every run factors.

/// The set-up of the shipped scene `name` at `mesh.n = n` with `contact.law = "none"` (and no
/// known solution, which needs its contact, where the scene has one).
pub fn setup_without_contact(name: &str, n: usize) -> problem::backend::Setup {
    let sets = [format!("mesh.n={n}"), "contact.law=none".into()];
    let without = [sets[0].clone(), sets[1].clone(), "~exact".into()];
    let (scene, _) = files::scene_file::load(name, &without)
        .or_else(|_| files::scene_file::load(name, &sets))
        .expect("scene");
    problem::backend::setup(scene.validate().expect("a valid scene"), None).expect("setup")
}
