//! The six stages of the tutorial, and the switches that turn them on and off.
//!
//! A stage is one step of the book. `--stage S` turns on every stage up to and
//! including `S`; `--without S` then turns single stages off again, so that a reader
//! can see what one step changes on its own.

use std::fmt;

/// Which tracer renders (`--engine`). Both give the same bits for every pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum Engine {
    /// The tracer the chapters show, one ray at a time in plain code (the module
    /// render): the default wherever a reader looks at pictures.
    #[default]
    Book,
    /// The same tracer, four rays at a time in SIMD lanes, with tile masks and a
    /// packet walk of the BVH (the module fast): the default of raystep bench and chart. It
    /// traces what it does not support with the book's engine.
    Fast,
}

impl Engine {
    /// `"book"` or `"fast"`.
    pub fn name(self) -> &'static str {
        match self {
            Engine::Book => "book",
            Engine::Fast => "fast",
        }
    }
}

impl fmt::Display for Engine {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// One step of the tutorial, in the order the book introduces them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, clap::ValueEnum)]
pub enum Stage {
    /// One ray per pixel; the picture shows each ray's direction.
    Rays,
    /// The nearest sphere along each ray, in its flat diffuse colour.
    Intersection,
    /// Black where something stands between the hit point and the light.
    Shadow,
    /// Ambient + diffuse + specular light.
    BlinnPhong,
    /// Mirror bounces, up to max_depth segments per pixel.
    Reflection,
    /// The floor (the scene's plane entries) takes part.
    Plane,
}

impl Stage {
    /// Every stage, in order.
    pub const ALL: [Stage; 6] = [
        Stage::Rays,
        Stage::Intersection,
        Stage::Shadow,
        Stage::BlinnPhong,
        Stage::Reflection,
        Stage::Plane,
    ];

    /// The name used on the command line and in folder names.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Rays => "rays",
            Stage::Intersection => "intersection",
            Stage::Shadow => "shadow",
            Stage::BlinnPhong => "blinn-phong",
            Stage::Reflection => "reflection",
            Stage::Plane => "plane",
        }
    }

    /// 1 for `rays` up to 6 for `plane`.
    pub fn number(self) -> usize {
        self as usize + 1
    }

    /// The folder `raystep stages` writes this stage into, e.g. `03-shadow`.
    pub fn folder(self) -> String {
        format!("{:02}-{}", self.number(), self.name())
    }

    /// Its label on the contact sheet and the page, e.g. `3 shadow`.
    pub fn label(self) -> String {
        format!("{} {}", self.number(), self.name())
    }

    /// The stage this one cannot work without, if any.
    pub fn needs(self) -> Option<Stage> {
        match self {
            Stage::Rays => None,
            Stage::Intersection => Some(Stage::Rays),
            _ => Some(Stage::Intersection),
        }
    }
}

impl fmt::Display for Stage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Which stages are on. Each field is one switch that turns one step on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stages {
    /// Primary rays are cast (always on in a valid set).
    pub rays: bool,
    /// Rays are intersected with the spheres.
    pub intersection: bool,
    /// Shadow rays decide whether a hit point sees the light (with the `auto`
    /// step, a point on a sphere's side away from the light is in shadow without
    /// one).
    pub shadow: bool,
    /// Hit points are lit by Blinn-Phong instead of showing their flat colour.
    pub blinn_phong: bool,
    /// Rays bounce off surfaces: up to `max_depth` segments per path, so at most
    /// `max_depth − 1` bounces.
    pub reflection: bool,
    /// `[[plane]]` entries take part.
    pub plane: bool,
}

impl Stages {
    /// Every stage on: the tutorial's final program.
    pub const ALL: Stages = Stages {
        rays: true,
        intersection: true,
        shadow: true,
        blinn_phong: true,
        reflection: true,
        plane: true,
    };

    /// Every stage up to and including `last`.
    pub fn up_to(last: Stage) -> Stages {
        let mut stages = Stages::ALL;
        for stage in Stage::ALL.into_iter().filter(|&s| s > last) {
            stages.set(stage, false);
        }
        stages
    }

    /// `--stage last --without s...`: the stages up to `last`, less those in
    /// `without`. A set in which an enabled stage needs a disabled one is refused,
    /// with the reason.
    pub fn select(last: Stage, without: &[Stage]) -> Result<Stages, String> {
        let mut stages = Stages::up_to(last);
        for &stage in without {
            if stage > last {
                return Err(format!(
                    "--without {stage} does nothing: --stage {last} leaves {stage} off already"
                ));
            }
            stages.set(stage, false);
        }
        for stage in Stage::ALL.into_iter().filter(|&s| stages.is_on(s)) {
            if let Some(needed) = stage.needs().filter(|&n| !stages.is_on(n)) {
                return Err(format!(
                    "stage `{stage}` cannot run without `{needed}`, which --without turns off: {}",
                    why_needed(stage)
                ));
            }
        }
        if !stages.rays {
            return Err("--without rays turns off every stage: nothing would be rendered".into());
        }
        Ok(stages)
    }

    /// Is `stage` on?
    pub fn is_on(self, stage: Stage) -> bool {
        match stage {
            Stage::Rays => self.rays,
            Stage::Intersection => self.intersection,
            Stage::Shadow => self.shadow,
            Stage::BlinnPhong => self.blinn_phong,
            Stage::Reflection => self.reflection,
            Stage::Plane => self.plane,
        }
    }

    fn set(&mut self, stage: Stage, on: bool) {
        let switch = match stage {
            Stage::Rays => &mut self.rays,
            Stage::Intersection => &mut self.intersection,
            Stage::Shadow => &mut self.shadow,
            Stage::BlinnPhong => &mut self.blinn_phong,
            Stage::Reflection => &mut self.reflection,
            Stage::Plane => &mut self.plane,
        };
        *switch = on;
    }
}

/// The names of the stages that are on, joined with `+`, e.g. `rays+intersection`.
impl fmt::Display for Stages {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let on: Vec<&str> = Stage::ALL
            .into_iter()
            .filter(|&s| self.is_on(s))
            .map(Stage::name)
            .collect();
        f.write_str(&on.join("+"))
    }
}

fn why_needed(stage: Stage) -> &'static str {
    match stage {
        Stage::Intersection => "there are no rays to intersect",
        Stage::Shadow => "a shadow ray starts at the hit point that intersection finds",
        Stage::BlinnPhong => "lighting needs the hit point and normal that intersection finds",
        Stage::Reflection => "a reflected ray starts at the hit point that intersection finds",
        Stage::Plane => "the plane is drawn by intersecting rays with it",
        Stage::Rays => "",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn up_to_turns_on_a_prefix() {
        let s = Stages::up_to(Stage::Shadow);
        assert!(s.rays && s.intersection && s.shadow);
        assert!(!s.blinn_phong && !s.reflection && !s.plane);
        assert_eq!(Stages::up_to(Stage::Plane), Stages::ALL);
        assert_eq!(s.to_string(), "rays+intersection+shadow");
    }

    #[test]
    fn without_turns_one_stage_off() {
        let s = Stages::select(Stage::Plane, &[Stage::Shadow]).unwrap();
        assert!(!s.shadow && s.blinn_phong && s.plane);
    }

    #[test]
    fn a_stage_without_what_it_needs_is_refused_with_the_reason() {
        let err = Stages::select(Stage::Shadow, &[Stage::Intersection]).unwrap_err();
        assert!(
            err.contains("`shadow` cannot run without `intersection`"),
            "{err}"
        );
        let err = Stages::select(Stage::Rays, &[Stage::Rays]).unwrap_err();
        assert!(err.contains("nothing would be rendered"), "{err}");
    }

    #[test]
    fn turning_off_a_stage_that_is_off_already_is_refused() {
        let err = Stages::select(Stage::Shadow, &[Stage::Plane]).unwrap_err();
        assert!(err.contains("--without plane does nothing"), "{err}");
    }

    #[test]
    fn folders_are_numbered_in_order() {
        let folders: Vec<String> = Stage::ALL.into_iter().map(Stage::folder).collect();
        assert_eq!(folders[0], "01-rays");
        assert_eq!(folders[3], "04-blinn-phong");
        assert_eq!(folders[5], "06-plane");
    }

    /// Every stage after `intersection` needs the hit point intersection finds,
    /// even when it is the only one left on beside `rays`: `--stage S --without
    /// intersection --without` every stage between is refused, naming S.
    #[test]
    fn each_stage_after_intersection_alone_is_refused_without_intersection() {
        let later = [
            Stage::Shadow,
            Stage::BlinnPhong,
            Stage::Reflection,
            Stage::Plane,
        ];
        for (i, &stage) in later.iter().enumerate() {
            let mut without = vec![Stage::Intersection];
            without.extend_from_slice(&later[..i]);
            let err = Stages::select(stage, &without).unwrap_err();
            assert!(
                err.contains(&format!("`{stage}` cannot run without `intersection`")),
                "{stage}: {err}"
            );
        }
    }
}
