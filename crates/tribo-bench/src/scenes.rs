//! The benchmark scenes (engine-neutral [`SceneFile`]s) and scene transformations.
//!
//! `large_pyramid`, `many_pyramids`, `tumbler` (`tumbler_benchmark`), `compounds`,
//! `junkyard`, `joint_grid`, `spinner`, `washer` and `rain` (`ragdoll_rain`) come from `tribo_scenes::scenes`; `smash` is built here following shared/SCENES.md §2 (Box2D v3's
//! `CreateSmash`). The scaling run's scenes are `tribo_scenes::scenes::scaling_rain(n)`.

use crate::engines::BoxError;
use crate::engines::Sim;
use tribo_scenes::format::{BodyKind, BodySpec, MaterialRef, MaterialSpec, SceneFile, ShapeSpec};

/// What the stability check of a scene looks at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CheckKind {
    /// Top box(es) must neither drop (more than 10 mm per stacked layer, i.e. twice Box2D's
    /// 5 mm linear slop that each resting contact may keep as penetration) nor drift
    /// sideways by 0.5 m or more.
    Pyramid {
        /// Boxes stacked under (and including) the top box, for the drop limit.
        stack_layers: u32,
    },
    /// The projectile must hit and plough into the block; momentum is conserved.
    Smash,
    /// Every box's centre, in the frame of the drum (the body named "drum", driven at ω by
    /// its motor: angle ω t), must stay inside the drum: |x|, |y| < 9.5 m (the walls' inner
    /// faces); the engine's own drum angle must match ω t within 0.01 rad.
    Tumbler,
    /// Joint grid: every body finite, and every jointed pair's centres less than
    /// `max_link` apart (the links are 1 m; a grid whose joints give way stretches or
    /// tears).
    JointGrid {
        /// Largest centre distance of two jointed bodies [m].
        max_link: f32,
    },
    /// Spinner: no body out of the ring (centre `radius` or more from the ring's centre: a
    /// body whose centre has crossed the one-sided chain is on its way out of the world) and
    /// the rotor (the body named "rotor") turning at its motor speed within 1 %.
    Spinner {
        /// The ring's radius plus a margin [m].
        radius: f32,
    },
    /// Every box's centre must stay within the washer's rim (`radius` of the ring centre,
    /// which moves at the ring's constant velocity), and the engine's own ring angle must
    /// match ω t within 0.01 rad.
    Washer {
        /// Inner radius of the rim [m].
        radius: f32,
    },
    /// Box2D's rain of ragdolls: no ragdoll body may end below the top of the shelf its
    /// group was dropped onto (a body lying on a shelf has its origin at least the 3 cm
    /// radius of its thinnest capsule above it, less the few millimetres a soft contact
    /// lets it sink), unless it fell off a shelf's end (|x| beyond the shelf); every body
    /// finite.
    RagdollRain,
    /// Every body's centre must stay inside the container: |x| < `half_width` (the walls'
    /// inner faces) and y > 0 (the floor's top face), but for at most `max_outside` bodies,
    /// which must then be above `catch_y` (caught, not fallen through everything).
    Rain {
        /// Inner half width of the container [m].
        half_width: f32,
        /// Bodies allowed outside (0: none).
        max_outside: usize,
        /// Lowest y [m] a body outside may have.
        catch_y: f32,
    },
}

/// A per-step hook ([`tribo_scenes::scenes::StepHook`]): called before step `n` (0 = the
/// untimed first step), inside the timing loop as Box2D's benchmark driver does; its
/// actions are applied to the engine by [`run_hook`].
pub type Hook = tribo_scenes::scenes::StepHook;

/// Runs a scene's hook before step `n` and applies what it asks to `sim`.
pub fn run_hook(hook: Hook, n: u32, sim: &mut dyn Sim, scene: &SceneFile) -> Result<(), BoxError> {
    use tribo_scenes::scenes::HookAction;
    let actions = hook(n, scene.dt, &mut |i| sim.position(i));
    for action in actions {
        match action {
            HookAction::SetVelocity {
                body,
                velocity,
                angular_velocity,
            } => sim.set_kinematic_velocity(body, velocity, angular_velocity)?,
            HookAction::Despawn { tag } => sim.despawn(tag)?,
            HookAction::Spawn { tag, batch } => sim.spawn(tag, batch)?,
        }
    }
    Ok(())
}

/// A benchmark scene.
pub struct BenchScene {
    /// Name on the command line and in the JSON.
    pub name: String,
    /// Builds the scene.
    pub build: Box<dyn Fn() -> SceneFile>,
    /// Which check applies.
    pub check: CheckKind,
    /// How the scene differs from Box2D's, printed under the table header ("" = none).
    pub note: &'static str,
    /// Called before every step, if any.
    pub hook: Option<Hook>,
}

impl BenchScene {
    fn new(name: &str, build: impl Fn() -> SceneFile + 'static, check: CheckKind) -> BenchScene {
        BenchScene {
            name: name.into(),
            build: Box::new(build),
            check,
            note: "",
            hook: None,
        }
    }
}

/// Every Box2D benchmark scene, in the order `all` runs them.
pub fn scenes() -> Vec<BenchScene> {
    vec![
        BenchScene::new(
            "large_pyramid",
            tribo_scenes::scenes::large_pyramid,
            CheckKind::Pyramid { stack_layers: 100 },
        ),
        BenchScene::new(
            "many_pyramids",
            tribo_scenes::scenes::many_pyramids,
            CheckKind::Pyramid { stack_layers: 10 },
        ),
        BenchScene::new("smash", smash, CheckKind::Smash),
        BenchScene::new("tumbler", tribo_scenes::scenes::tumbler_benchmark, CheckKind::Tumbler),
        BenchScene {
            note: "check: body origins (the triangles' base centres) inside the container but for 1 % \
                   that may bounce over a wall onto the catch segment at y = -80 m (Box2D loses 2)",
            ..BenchScene::new(
                "compounds",
                tribo_scenes::scenes::compounds,
                CheckKind::Rain {
                    half_width: tribo_scenes::scenes::COMPOUNDS_INNER_HALF_WIDTH,
                    max_outside: 30,
                    catch_y: -81.0,
                },
            )
        },
        BenchScene {
            hook: Some(tribo_scenes::scenes::junkyard_hook),
            ..BenchScene::new(
                "junkyard",
                tribo_scenes::scenes::junkyard,
                CheckKind::Rain {
                    half_width: tribo_scenes::scenes::JUNKYARD_INNER_HALF_WIDTH,
                    max_outside: 0,
                    catch_y: 0.0,
                },
            )
        },
        BenchScene::new(
            "joint_grid",
            tribo_scenes::scenes::joint_grid,
            CheckKind::JointGrid { max_link: 1.25 },
        ),
        BenchScene {
            note: "the ring is a one-sided chain loop of 360 pieces: Box2D's chain, Tribo's chain (ghost-vertex \
                   smoothing as Box2D), Rapier's oriented polyline (one-sided, no smoothing)",
            ..BenchScene::new(
                "spinner",
                tribo_scenes::scenes::spinner,
                CheckKind::Spinner {
                    // A body held by the ring has its centre inside it; 0.5 m of margin for
                    // the chord of a 1° piece and a body pressed there by the rotor's tip,
                    // which reaches 0.2 m past the ring at its lowest point.
                    radius: tribo_scenes::scenes::SPINNER_RADIUS + 0.5,
                },
            )
        },
        BenchScene {
            note: "Rapier: group indices through a contact-filter hook; each joint's spring takes Rapier's one \
                   motor (acceleration-based, ω² and 2ζω), the joint friction beside it is dropped",
            hook: Some(tribo_scenes::scenes::ragdoll_rain_hook),
            ..BenchScene::new("rain", tribo_scenes::scenes::ragdoll_rain, CheckKind::RagdollRain)
        },
        BenchScene {
            note: "Box2D's boxes report hit events; no engine reports them here",
            ..BenchScene::new(
                "washer",
                tribo_scenes::scenes::washer,
                CheckKind::Washer {
                    radius: tribo_scenes::scenes::WASHER_RIM_INNER,
                },
            )
        },
    ]
}

/// The scaling scene with `n` bodies ([`tribo_scenes::scenes::scaling_rain`]), named
/// `scaling_rain_<n>`.
pub fn scaling_scene(n: usize) -> BenchScene {
    let mut b = BenchScene::new(
        &format!("scaling_rain_{n}"),
        move || tribo_scenes::scenes::scaling_rain(n),
        CheckKind::Rain {
            half_width: tribo_scenes::scenes::rain_half_width(n),
            max_outside: 0,
            catch_y: 0.0,
        },
    );
    b.note = "not a Box2D scene: container width ∝ n (constant pile depth), sleep off";
    b
}

fn box_shape(hx: f32, hy: f32, material: MaterialSpec) -> ShapeSpec {
    ShapeSpec {
        kind: "box".into(),
        half_extents: Some([hx, hy]),
        material: Some(MaterialRef::Inline(material)),
        ..ShapeSpec::default()
    }
}

fn dynamic_body(name: Option<String>, position: [f32; 2], shapes: Vec<ShapeSpec>) -> BodySpec {
    BodySpec {
        name,
        kind: BodyKind::Dynamic,
        position,
        gravity_scale: 1.0,
        awake: true,
        shapes,
        ..BodySpec::default()
    }
}

/// Box2D v3's `smash` benchmark scene (SCENES.md §2): no gravity; a heavy box (half 4×4,
/// density 8) at (−20, 0) moving at 40 m/s into a block of 120 × 80 small boxes (half
/// 0.2 × 0.2, density 1, friction 0.6) created asleep. 300 steps, sleep on.
pub fn smash() -> SceneFile {
    let mut s = SceneFile {
        description: Some("Box2D v3 benchmark smash".into()),
        gravity: [0.0, 0.0],
        dt: 1.0 / 60.0,
        substeps: 4,
        steps: 300,
        enable_sleep: true,
        materials: Default::default(),
        bodies: Vec::with_capacity(1 + 120 * 80),
        joints: Vec::new(),
    };
    // Box2D shape defaults: friction 0.6, restitution 0, density 1.
    let projectile_material = MaterialSpec {
        density: Some(8.0),
        friction: Some(0.6),
        ..MaterialSpec::default()
    };
    let mut projectile = dynamic_body(
        Some("projectile".into()),
        [-20.0, 0.0],
        vec![box_shape(4.0, 4.0, projectile_material)],
    );
    projectile.linear_velocity = [40.0, 0.0];
    s.bodies.push(projectile);
    let target_material = MaterialSpec {
        density: Some(1.0),
        friction: Some(0.6),
        ..MaterialSpec::default()
    };
    for i in 0..120 {
        for j in 0..80 {
            let x = 30.0 + 0.4 * i as f32;
            let y = 0.4 * (j as f32 - 40.0);
            let mut b = dynamic_body(None, [x, y], vec![box_shape(0.2, 0.2, target_material.clone())]);
            b.awake = false;
            s.bodies.push(b);
        }
    }
    s
}

/// The scene with every shape's static friction scaled by `factor` (μd unchanged): every
/// shape gets its resolved material written in place with μs = factor · μs.
pub fn scale_static_friction(scene: &SceneFile, factor: f32) -> SceneFile {
    let mut out = scene.clone();
    for body in &mut out.bodies {
        for shape in &mut body.shapes {
            let mut m = scene.shape_material(shape);
            m.friction_static *= factor;
            shape.material = Some(MaterialRef::Inline(MaterialSpec::from_material(&m)));
        }
    }
    out.materials.clear();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smash_matches_scenes_md() {
        let s = smash();
        assert!(s.validate().is_ok());
        assert_eq!(s.bodies.len(), 9601);
        assert_eq!(s.bodies.iter().filter(|b| !b.awake).count(), 9600);
        let m = s.shape_material(&s.bodies[0].shapes[0]);
        assert_eq!((m.density, m.friction_static, m.friction_dynamic), (8.0, 0.6, 0.6));
    }

    #[test]
    fn scaling_keeps_dynamic_friction() {
        let s = scale_static_friction(&tribo_scenes::scenes::large_pyramid(), 1.5);
        assert!(s.validate().is_ok());
        let m = s.shape_material(&s.bodies[1].shapes[0]);
        assert!((m.friction_static - 0.9).abs() < 1e-6 && (m.friction_dynamic - 0.6).abs() < 1e-6);
    }
}

/// The rain's check ([`CheckKind::RagdollRain`]): (bodies, bodies below their shelf's top,
/// bodies off a shelf's end, lowest height above its shelf's top [m], all finite).
pub fn rain_census(sim: &mut dyn Sim) -> (usize, usize, usize, f32, bool) {
    use tribo_scenes::scenes::{
        ragdoll_rain_shelf_top, RAGDOLL_BODIES, RAGDOLL_RAIN_COLUMNS, RAGDOLL_RAIN_PER_GROUP,
        RAGDOLL_RAIN_SHELF_HALF_LENGTH,
    };
    let (mut bodies, mut below, mut off, mut lowest, mut finite) = (0, 0, 0, f32::INFINITY, true);
    for column in 0..RAGDOLL_RAIN_COLUMNS {
        for (k, p) in sim.spawned_positions(column).into_iter().enumerate() {
            bodies += 1;
            let row = k / (RAGDOLL_RAIN_PER_GROUP * RAGDOLL_BODIES);
            if !(p[0].is_finite() && p[1].is_finite()) {
                finite = false;
            } else if p[0].abs() > RAGDOLL_RAIN_SHELF_HALF_LENGTH {
                off += 1;
            } else {
                let above = p[1] - ragdoll_rain_shelf_top(row);
                lowest = lowest.min(above);
                below += (above < 0.0) as usize;
            }
        }
    }
    (bodies, below, off, lowest, finite)
}
