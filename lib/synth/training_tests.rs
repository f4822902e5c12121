//! Tests of the training zoo: the actions do what their names promise (idle stands, run is
//! faster, turn turns, walk-stop-walk stops between its boundaries), feet plant without
//! sliding in every stepping action, variants change proportions and joint counts, and the
//! example creatures are variant 0.

use super::tests::planting;
use super::*;
use crate::skeleton::roles;

/// Short clips keep the whole table fast in debug builds; long enough for several steps.
const FRAMES: usize = 150;

fn clip(name: &str, variant: u64, action: Action) -> TrainingClip {
    training_clip(name, variant, action, 11, FRAMES).unwrap_or_else(|| panic!("{name} {action:?}"))
}

/// Root positions on the ground plane, per frame.
fn root_track(c: &TrainingClip) -> Vec<DVec3> {
    let world = c.motion.forward_kinematics(&c.skeleton);
    (0..c.motion.frames).map(|f| world.position(f, 0) * DVec3::new(1.0, 0.0, 1.0)).collect()
}

/// Mean horizontal root speed over frames `a..b` (m/s), measured over whole seconds so the
/// gait's own sway averages out.
fn mean_speed(track: &[DVec3], a: usize, b: usize) -> f64 {
    track[b - 1].distance(track[a]) / ((b - 1 - a) as f64 * FRAME_TIME)
}

/// Lowest height any joint or End Site reaches in the clip.
fn lowest_point(c: &TrainingClip) -> f64 {
    let world = c.motion.forward_kinematics(&c.skeleton);
    let mut lowest = f64::INFINITY;
    for f in 0..c.motion.frames {
        for (j, joint) in c.skeleton.joints.iter().enumerate() {
            let at = world.position(f, j);
            lowest = lowest.min(at.y);
            for e in &joint.end_sites {
                lowest = lowest.min((at + world.rotations[f * world.joints + j] * *e).y);
            }
        }
    }
    lowest
}

fn main_action(name: &str) -> Action {
    if actions(name).contains(&Action::Walk) {
        Action::Walk
    } else {
        Action::Undulate
    }
}

#[test]
fn every_creature_has_three_to_five_actions_and_unknowns_are_none() {
    for name in creature_names() {
        let list = actions(name);
        assert!((3..=5).contains(&list.len()), "{name}: {list:?}");
        assert!(list.contains(&Action::Idle) && list.contains(&Action::Turn), "{name}: {list:?}");
    }
    assert!(actions("unicorn").is_empty());
    assert!(training_clip("unicorn", 0, Action::Walk, 1, 100).is_none());
    assert!(training_clip("snake", 0, Action::Walk, 1, 100).is_none(), "snakes do not walk");
    assert!(proportions("unicorn", 3).is_none());
    // Frame counts are clamped, never a panic.
    assert_eq!(training_clip("fish", 0, Action::Idle, 1, 0).unwrap().motion.frames, *CLIP_FRAMES.start());
}

#[test]
fn clips_are_deterministic_and_seeds_matter() {
    for name in creature_names() {
        let action = main_action(name);
        let text = |seed: u64| {
            let c = training_clip(name, 2, action, seed, 60).unwrap();
            bvh::write_string(&c.motion.to_bvh(&c.skeleton))
        };
        assert_eq!(text(5), text(5), "{name}");
        assert_ne!(text(5), text(6), "{name}: the seed changes nothing");
    }
}

#[test]
fn variant_zero_is_the_example_creature_and_others_differ() {
    for name in creature_names() {
        let (example, _) = creature(name, DEFAULT_SEED).unwrap();
        let v0 = clip(name, 0, main_action(name)).skeleton;
        assert_eq!(v0, example, "{name}: variant 0 is not the example body");
        let bones0 = v0.bone_lengths();
        for variant in 1..4 {
            let v = clip(name, variant, main_action(name)).skeleton;
            let p = proportions(name, variant).unwrap();
            assert!((0.6..=1.5).contains(&p.size), "{name} v{variant}: size {}", p.size);
            if v.len() == v0.len() {
                let changed = v.bone_lengths().iter().zip(&bones0).filter(|(a, b)| (*a - *b).abs() > 1e-6).count();
                assert!(changed > v0.len() / 2, "{name} v{variant}: only {changed} bones changed");
            }
            // Names stay those of the family: roles and sides keep working on every variant.
            assert_eq!(v.joints[0].name, v0.joints[0].name, "{name} v{variant}");
        }
    }
}

#[test]
fn variants_change_joint_counts_where_bodies_repeat() {
    for name in ["quadruped", "dragon", "centipede", "snake", "fish"] {
        let counts: std::collections::BTreeSet<usize> = (0..10).map(|v| clip(name, v, main_action(name)).skeleton.len()).collect();
        assert!(counts.len() >= 3, "{name}: joint counts {counts:?}");
    }
    for name in ["biped", "spider", "crab", "bird"] {
        let n = creature(name, 1).unwrap().0.len();
        assert!((0..4).all(|v| clip(name, v, main_action(name)).skeleton.len() == n), "{name}");
    }
}

#[test]
fn every_action_is_finite_and_stays_above_the_ground() {
    for name in creature_names() {
        for &action in actions(name) {
            for variant in [0, 3] {
                let c = clip(name, variant, action);
                assert_eq!(c.motion.frames, FRAMES);
                assert!(c.motion.rotations.iter().all(|q| q.is_finite()), "{name} {action:?}: rotation");
                assert!(c.motion.translations.iter().all(|t| t.is_finite()), "{name} {action:?}: translation");
                let lowest = lowest_point(&c);
                let h = c.skeleton.rest_height().max(0.05);
                assert!(lowest > -0.01 * h, "{name} v{variant} {action:?}: a joint or End Site reaches y = {lowest:.4}");
            }
        }
    }
}

#[test]
fn idle_stands_while_walking_travels() {
    for name in creature_names() {
        let extent = creature(name, 1).unwrap().0.rest_extent();
        let idle = root_track(&clip(name, 1, Action::Idle));
        let walk = root_track(&clip(name, 1, main_action(name)));
        let wander = idle.iter().map(|p| p.distance(idle[0])).fold(0.0, f64::max);
        let travel = walk[FRAMES - 1].distance(walk[0]);
        assert!(wander < 0.1 * extent, "{name}: idle root wanders {wander:.3} (extent {extent:.3})");
        assert!(travel > 0.5 * extent, "{name}: walk travels only {travel:.3}");
    }
}

#[test]
fn the_fast_action_is_faster() {
    for name in creature_names() {
        let fast = [Action::Run, Action::Hop, Action::UndulateFast].into_iter().find(|a| actions(name).contains(a));
        let fast = fast.unwrap_or_else(|| panic!("{name}: no fast action"));
        let slow = mean_speed(&root_track(&clip(name, 2, main_action(name))), 0, FRAMES);
        let quick = mean_speed(&root_track(&clip(name, 2, fast)), 0, FRAMES);
        assert!(quick > 1.3 * slow, "{name}: {fast:?} {quick:.3} m/s vs {slow:.3} m/s");
    }
}

#[test]
fn running_and_hopping_leave_the_ground() {
    for (name, action) in [("biped", Action::Run), ("bird", Action::Hop)] {
        let c = clip(name, 0, action);
        let world = c.motion.forward_kinematics(&c.skeleton);
        let (feet, _) = roles::feet(&c.skeleton);
        let h = c.skeleton.rest_height();
        let ground = (0..FRAMES).flat_map(|f| feet.iter().map(move |&j| (f, j))).map(|(f, j)| world.position(f, j).y);
        let ground = ground.fold(f64::INFINITY, f64::min);
        let airborne = (0..FRAMES).filter(|&f| feet.iter().all(|&j| world.position(f, j).y > ground + 0.01 * h)).count();
        assert!(airborne as f64 > 0.06 * FRAMES as f64, "{name} {action:?}: airborne on {airborne} frames");
    }
}

#[test]
fn turning_changes_the_heading() {
    for name in creature_names() {
        let track = root_track(&clip(name, 1, Action::Turn));
        // Direction of travel over the first and the last second.
        let first = (track[30] - track[0]).normalize();
        let last = (track[FRAMES - 1] - track[FRAMES - 31]).normalize();
        let angle = first.dot(last).clamp(-1.0, 1.0).acos().to_degrees();
        assert!(angle > 40.0, "{name}: heading changes {angle:.1} degrees");
    }
}

#[test]
fn walk_stop_walk_stands_between_its_boundaries() {
    for name in creature_names() {
        if !actions(name).contains(&Action::WalkStopWalk) {
            continue;
        }
        let c = clip(name, 1, Action::WalkStopWalk);
        let [stop, go] = c.boundaries[..] else { panic!("{name}: boundaries {:?}", c.boundaries) };
        assert!(go >= stop + 25 && stop > 20 && go + 20 < FRAMES, "{name}: boundaries {stop}, {go}");
        let track = root_track(&c);
        let cruise = mean_speed(&track, 0, stop.min(30));
        let standing = mean_speed(&track, stop, go + 1);
        let after = mean_speed(&track, go, FRAMES);
        assert!(standing < 0.02 * cruise, "{name}: {standing:.4} m/s while standing vs {cruise:.3}");
        assert!(cruise > 0.0 && after > 0.3 * cruise, "{name}: {cruise:.3} m/s before, {after:.3} after");
        // Every foot is down while standing: none moves between the boundaries.
        let world = c.motion.forward_kinematics(&c.skeleton);
        let (feet, _) = roles::feet(&c.skeleton);
        for &j in &feet {
            let moved = world.position(go, j).distance(world.position(stop, j));
            assert!(moved < 1e-3 * c.skeleton.rest_extent(), "{name}/{}: moves {moved} while standing", c.skeleton.joints[j].name);
        }
    }
}

#[test]
fn stance_feet_do_not_slide() {
    for name in creature_names() {
        for &action in actions(name) {
            // Limbless bodies have no named feet; idle feet never leave the ground.
            if matches!(*name, "snake" | "fish") || action == Action::Idle {
                continue;
            }
            for variant in [0, 2] {
                let c = clip(name, variant, action);
                let rows = planting(&c.skeleton, &c.motion);
                assert!(!rows.is_empty(), "{name} {action:?}: no feet");
                for (joint, share, median, _) in &rows {
                    assert!(*share > 0.2, "{name} v{variant} {action:?}/{joint}: grounded {share:.2}");
                    assert!(*median < 0.15, "{name} v{variant} {action:?}/{joint}: stance speed {median:.3} x root");
                }
            }
        }
    }
}

#[test]
fn the_training_zoo_writes_one_folder_per_body() {
    let dir = std::env::temp_dir().join(format!("menagerie-training-zoo-{}", std::process::id()));
    let written = write_training_zoo(&dir, 1, 1, 3).unwrap();
    let clips: usize = creature_names().iter().map(|n| actions(n).len()).sum();
    assert_eq!(written.len(), clips);
    let walk = dir.join("quadruped_v0").join("walk_0.bvh");
    assert!(written.contains(&walk));
    let parsed = bvh::parse(&std::fs::read_to_string(&walk).unwrap(), "walk").unwrap();
    assert!((150..=300).contains(&parsed.frames), "{} frames", parsed.frames);
    let index = std::fs::read_to_string(dir.join("boundaries.tsv")).unwrap();
    let stop = index.lines().find(|l| l.starts_with("biped_v0/walk_stop_walk_0.bvh")).unwrap();
    assert_eq!(stop.split('\t').nth(2).unwrap().split(',').count(), 2, "{stop}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The same checks over many more bodies (about 6 s in a debug build: `cargo test --lib
/// synth::training_tests -- --ignored`). Extreme proportions are where legs run out of reach.
/// Rig variants (from `RIG_VARIANTS`) are measured before their axes and units are converted,
/// since the checks assume Y-up metres; their names, counts and extra anatomy are kept.
#[test]
#[ignore]
fn feet_plant_on_every_variant() {
    for name in creature_names() {
        for &action in actions(name) {
            if matches!(*name, "snake" | "fish") || action == Action::Idle {
                continue;
            }
            for variant in 0..24 {
                let (c, _) = super::training::native_clip(name, variant, action, 11, FRAMES).unwrap();
                let rows = planting(&c.skeleton, &c.motion);
                let worst = rows.iter().map(|r| r.2).fold(0.0, f64::max);
                let share = rows.iter().map(|r| r.1).fold(1.0, f64::min);
                let lowest = lowest_point(&c) / c.skeleton.rest_height();
                let what = format!("{name} v{variant} {action:?} {:?}", proportions(name, variant));
                assert!(worst < 0.1 && share > 0.2 && lowest > -0.005, "{what}: stance {worst:.3} share {share:.2} low {lowest:.4}");
            }
        }
    }
}

#[test]
fn foot_plans_reduce_to_the_constant_speed_gait() {
    use super::route::{speed_profile, Clock, FootPlan, FootSpec, Route};
    // Straight on at constant speed, the general planner must place feet exactly where the
    // example creatures' closed-form gait does.
    let gait = Gait { period: 0.9, duty: 0.65, stride: 0.5, lift: 0.06 };
    let route = Route::new(-5.0, 10.0, 0.0, 0.0, speed_profile(gait.speed(), None, 0.6), |_| 0.0);
    let clock = Clock { period: gait.period, duty: gait.duty, pause: None };
    for touchdown in [0.0, 0.3, 0.75] {
        let home = v3(0.1, 0.0, 0.4);
        let plan = FootPlan::new(&route, &clock, &FootSpec { home, lag: 0.0, touchdown }, 6.0, true, gait.half_reach(), gait.lift);
        for f in 0..150 {
            let t = f as f64 * FRAME_TIME;
            let (now, want) = (plan.at(t), gait.foot(t, touchdown));
            let want = v3(home.x, want.lift, home.z + want.forward);
            assert!(now.at.distance(want) < 1e-6, "touchdown {touchdown}, t {t:.3}: {} vs {want}", now.at);
        }
    }
    // Along a curve the track keeps its arc length and turns by curvature x distance.
    let curve = Route::new(-1.0, 5.0, 0.0, 0.0, |_| 1.0, |_| 0.5);
    assert!((curve.s_at(4.0) - 4.0).abs() < 1e-9);
    assert!((curve.at_time(4.0).yaw - 2.0).abs() < 1e-6, "{}", curve.at_time(4.0).yaw);
    assert!(curve.at_arc(2.0).pos.distance(curve.at_time(2.0).pos) < 1e-6);
}
