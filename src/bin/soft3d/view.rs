//! What a render sees: the camera (scene, fitted or the user's), the lights and the options,
//! from the arguments; and at an animation frame, the scene's camera and lights where its
//! tracks put them ([`posed_view`]).

use super::*;

#[derive(Clone)]
pub(crate) struct View {
    pub(crate) camera: Camera,
    pub(crate) lights: Lights<8>,
    pub(crate) opts: RenderOptions,
    pub(crate) background: [u8; 3],
    pub(crate) width: u16,
    pub(crate) height: u16,
    pub(crate) bands: u16,
    /// Threads drawing the bands (at most one a band).
    pub(crate) threads: u16,
    /// The animation frame to pose the model at, and the group (`--frame`, `--animation`).
    pub(crate) pose: Option<(f32, Option<usize>)>,
    /// What of the view follows the scene's animated camera and lights.
    pub(crate) follows: Follows,
}

/// What of a [`View`] follows the scene's camera and lights when their tracks move them, and
/// how its camera is rebuilt then.
#[derive(Clone, Copy)]
pub(crate) struct Follows {
    /// The eye and target are the scene camera's (no `--eye`, `--target` or `--fit`).
    pub(crate) eye: bool,
    /// The field of view is the scene camera's (no `--fov`).
    pub(crate) fov: bool,
    /// The lights are the scene's (no `--light`).
    pub(crate) lights: bool,
    /// The camera's up direction, aspect and field of view (the still one), and its height
    /// when orthographic.
    pub(crate) up: Vec3,
    pub(crate) aspect: f32,
    pub(crate) fov_y: f32,
    pub(crate) ortho_height: Option<f32>,
}

/// How much of the frame's limiting dimension a fitted model fills (see `--fit`).
pub(crate) const FIT_FILL: f32 = 0.95;

/// Near and far planes for an eye at `eye` that take in the whole of `model` (its bounding
/// sphere, with 1% to spare): what `--eye` and `--target` get unless `--near` and `--far` are
/// given.
pub(crate) fn fitted_planes(eye: Vec3, model: &Model<'_>) -> (f32, f32) {
    let (centre, radius) = model.bounds().unwrap_or((Vec3::ZERO, 1.0));
    let (d, r) = (eye.distance(centre), radius * 1.01);
    let far = (d + r).max(1e-3);
    ((d - r).max(far * 1e-3), far)
}

/// The lights of the render: the scene's (at most 8), or `--light`'s in their place, with
/// `--specular`; a warning for each thing left out.
pub(crate) fn scene_lights(args: &RenderArgs, model: &Model<'_>) -> Result<Lights<8>> {
    let mut lights = Lights::<8>::from_model(model);
    if model.light_count() > 8 {
        eprintln!(
            "warning: the scene has {} lights; soft3d draws 8: the last {} are left out",
            model.light_count(),
            model.light_count() - 8
        );
    }
    if !args.light.is_empty() {
        if model.light_count() > 0 {
            eprintln!("warning: --light replaces the scene's {} light(s) and its ambient light", model.light_count());
        }
        lights = Lights::new(Vec3::ZERO);
        for l in &args.light {
            let light = if let Some(v) = l.strip_prefix("dir:") {
                let dir = parse_vec3(v, "--light dir")?;
                if dir == Vec3::ZERO {
                    return Err(format!("--light: a direction must not be zero, got {l:?}"));
                }
                Lights::<8>::directional(dir, 1.0)
            } else if let Some(v) = l.strip_prefix("point:") {
                Lights::<8>::point(parse_vec3(v, "--light point")?, 1.0)
            } else {
                return Err(format!("--light: expected dir:x,y,z or point:x,y,z, got {l:?}"));
            };
            lights.push(light).map_err(|_| "--light: at most 8 lights".to_string())?;
        }
    }
    if let Some(power) = args.specular {
        if args.shading == ShadingArg::Phong {
            eprintln!(
                "warning: --specular is not drawn with --shading phong (its per-pixel light has no specular term)"
            );
        }
        lights.specular = Vec3::ONE;
        lights.shininess = power;
    }
    Ok(lights)
}

pub(crate) fn make_view(args: &RenderArgs, model: &Model<'_>) -> Result<View> {
    let (width, height) = parse_size(&args.size)?;
    if model.draw_counts().0 == 0 {
        return Err(format!("{}: the scene has no triangles to draw", args.input.display()));
    }
    let aspect = width as f32 / height.max(1) as f32;
    let scene_cam = model.camera();
    let fov = args.fov.or(scene_cam.map(|c| c.fov)).unwrap_or(0.8);
    let framing = Camera::framing(model, fov, aspect).map_err(|e| e.to_string())?;
    let (default_eye, default_target) = match &scene_cam {
        Some(c) => (c.position, c.target),
        None => (framing.eye, framing.target),
    };
    let eye = args.eye.as_deref().map(|s| parse_vec3(s, "--eye")).transpose()?.unwrap_or(default_eye);
    let target = args.target.as_deref().map(|s| parse_vec3(s, "--target")).transpose()?.unwrap_or(default_target);
    let up = args.up.as_deref().map(|s| parse_vec3(s, "--up")).transpose()?.unwrap_or(Vec3::Y);
    let moved = args.eye.is_some() || args.target.is_some();
    // `--fit`, or a scene without a camera of its own: closer, along the same direction.
    let fitted = (args.fit || (scene_cam.is_none() && !moved))
        .then(|| match args.camera {
            CameraKind::Perspective => Camera::fit(model, (target - eye, up), fov, aspect, FIT_FILL),
            CameraKind::Ortho => Camera::fit_orthographic(model, (target - eye, up), aspect, FIT_FILL),
        })
        .transpose()
        .map_err(|e| camera_error(e, (eye, target, up)))?;
    let (eye, target) = fitted.map_or((eye, target), |c| (c.eye, c.target));
    // A camera the user moved sees the model from elsewhere: its planes are fitted to it.
    let (default_near, default_far) = match (&fitted, &scene_cam, moved) {
        (Some(c), _, _) => (c.near, c.far),
        (None, _, true) => fitted_planes(eye, model),
        (None, Some(c), false) => (c.near, c.far),
        (None, None, false) => (framing.near, framing.far),
    };
    let far = args.far.unwrap_or(default_far);
    // A near plane beyond the user's far plane would leave nothing: theirs decides.
    let near = args.near.unwrap_or(if default_near < far { default_near } else { far * 1e-3 });
    if near >= far {
        return Err(format!("--far: must be beyond the near plane at {near}, got {far} (--near, --far)"));
    }
    let ortho_height = match args.camera {
        CameraKind::Perspective => None,
        CameraKind::Ortho => {
            // The fitted size, else the bounding sphere's diameter.
            let fitted_height = fitted.and_then(|c| c.orthographic_size()).map(|(_, h)| h);
            let diameter = 2.0 * model.bounds().map_or(1.0, |(_, radius)| radius);
            let h = args.ortho_height.or(fitted_height).unwrap_or(diameter);
            if !(h.is_finite() && h > 0.0) {
                return Err(format!("--ortho-height: the scene's bounds give {h}: give a finite size above 0"));
            }
            Some(h)
        }
    };
    let follows = Follows {
        eye: scene_cam.is_some() && fitted.is_none() && !moved,
        fov: scene_cam.is_some() && args.fov.is_none(),
        lights: args.light.is_empty(),
        up,
        aspect,
        fov_y: fov,
        ortho_height,
    };
    let camera = build_camera(&follows, (eye, target), fov, (near, far))?;
    let lights = scene_lights(args, model)?;
    let opts = RenderOptions { fog: fog(args, model)?, ..render_options(args) };
    let threads = args.threads.unwrap_or_else(|| {
        std::thread::available_parallelism().map_or(1, |n| u16::try_from(n.get()).unwrap_or(256).min(256))
    });
    let bands = match args.bands {
        Some(b) if b == 0 || b > height => {
            return Err(format!("--bands: must be 1..={height} (the frame's height), got {b}"))
        }
        Some(b) => b,
        // Four a thread: the busy rows of a scene spread over all of them.
        None => threads.saturating_mul(4).min(height),
    };
    let background = parse_rgb(&args.background, "--background")?;
    let pose = animation_pose(args, model)?;
    Ok(View { camera, lights, opts, background, width, height, bands, threads: threads.min(bands), pose, follows })
}

/// The camera looking from `eye` at `target` with `follows`' up, aspect and projection.
fn build_camera(follows: &Follows, (eye, target): (Vec3, Vec3), fov: f32, (near, far): (f32, f32)) -> Result<Camera> {
    let (up, aspect) = (follows.up, follows.aspect);
    match follows.ortho_height {
        None => Camera::perspective_up((eye, target, up), fov, aspect, near, far),
        Some(h) => Camera::orthographic_up((eye, target, up), h * aspect, h, near, far),
    }
    .map_err(|e| camera_error(e, (eye, target, up)))
}

/// `view` at its animation frame: with the scene's camera and lights where the scene's tracks
/// put them, as far as `view` follows them ([`Follows`]); `view` itself without a frame or
/// when nothing of it moves.
pub(crate) fn posed_view(view: &View, model: &Model<'_>) -> Result<View> {
    let (Some((frame, group)), Some(a)) = (view.pose, model.animation()) else { return Ok(view.clone()) };
    let moves_camera = a.camera().is_some() && (view.follows.eye || view.follows.fov);
    let moves_lights = a.animated_light_count() > 0 && view.follows.lights;
    if !moves_camera && !moves_lights {
        return Ok(view.clone());
    }
    let (nodes, weights) = pose_memory(a.node_count(), a.palette_count(), a.weight_count());
    let (mut node_memory, mut weight_memory) = (vec![Mat4::IDENTITY; nodes], vec![0.0f32; weights]);
    let mut pose = Pose::new(&mut node_memory, &mut weight_memory);
    pose.evaluate(&a, frame, group).map_err(|e| format!("--frame: {e}"))?;
    let mut posed = view.clone();
    if moves_lights {
        for (i, light) in posed.lights.lights.iter_mut().enumerate().take(model.light_count()) {
            *light = pose.light(&a, i, *light);
        }
    }
    if let (Some(still), true) = (model.camera(), moves_camera) {
        let c = pose.camera(&a, still);
        let f = &view.follows;
        let (eye, target) = if f.eye { (c.position, c.target) } else { (view.camera.eye, view.camera.target) };
        let fov = if f.fov { c.fov } else { f.fov_y };
        let planes = (view.camera.near, view.camera.far);
        posed.camera = build_camera(f, (eye, target), fov, planes)
            .map_err(|e| format!("--frame {frame}: the scene's camera at this frame: {e}"))?;
    }
    Ok(posed)
}

/// `--fog` and `--fog-color` over the scene's fog.
fn fog(args: &RenderArgs, model: &Model<'_>) -> Result<Option<Fog>> {
    let scene = model.fog();
    let default_color = scene.map_or(Vec3::new(0.2, 0.2, 0.3), |f| f.color);
    let color = match &args.fog_color {
        Some(c) => Vec3::from_array(parse_rgb(c, "--fog-color")?.map(|v| f32::from(v) / 255.0)),
        None => default_color,
    };
    let Some(spec) = &args.fog else {
        return Ok(scene.map(|f| Fog { color, ..f }));
    };
    let expected = "off, exp:DENSITY, exp2:DENSITY or linear:START,END";
    let number = |s: &str| s.trim().parse::<f32>().ok().filter(|x| x.is_finite());
    let (mode, params) = spec.split_once(':').unwrap_or((spec.as_str(), ""));
    let fog = match (mode, params.split(',').map(number).collect::<Option<Vec<f32>>>().as_deref()) {
        ("off", _) if params.is_empty() => return Ok(None),
        ("exp" | "exp2", Some(&[density])) if density >= 0.0 => {
            let mode = if mode == "exp" { FogMode::Exp } else { FogMode::Exp2 };
            Fog { density, ..Fog::new(mode, color) }
        }
        ("linear", Some(&[start, end])) => Fog { start, end, ..Fog::new(FogMode::Linear, color) },
        _ => return Err(format!("--fog: expected {expected} (a density at least 0), got {spec:?}")),
    };
    Ok(Some(fog))
}

/// `--frame` and `--animation`: the frame and the group (by name) to pose the model at.
fn animation_pose(args: &RenderArgs, model: &Model<'_>) -> Result<Option<(f32, Option<usize>)>> {
    let Some(frame) = args.frame else {
        return match &args.animation {
            Some(_) => Err("--animation: give the frame to pose at with --frame".into()),
            None => Ok(None),
        };
    };
    if !frame.is_finite() {
        return Err(format!("--frame: must be a finite number, got {frame}"));
    }
    let group = match &args.animation {
        None => None,
        Some(name) => {
            let animation = model.animation().ok_or("--animation: the scene has no animations")?;
            let found = animation.group_named(name);
            let names: Vec<&str> =
                (0..animation.group_count()).filter_map(|g| animation.group(g)).map(|g| g.name()).collect();
            Some(found.ok_or_else(|| format!("--animation: no group {name:?} (the scene has {})", names.join(", ")))?)
        }
    };
    Ok(Some((frame, group)))
}

/// The drawing options the arguments ask for.
pub(crate) fn render_options(args: &RenderArgs) -> RenderOptions {
    RenderOptions {
        shading: match args.shading {
            ShadingArg::Unlit => Shading::Unlit,
            ShadingArg::Flat => Shading::Flat,
            ShadingArg::Gouraud => Shading::Gouraud,
            ShadingArg::Phong => Shading::Phong,
        },
        mode: match args.mode {
            ModeArg::Solid => Mode::Solid,
            ModeArg::Wire => Mode::Wireframe,
            ModeArg::Points => Mode::Points,
            ModeArg::SolidWire => Mode::SolidWireframe,
        },
        filter: match args.filter {
            FilterArg::Nearest => Filter::Nearest,
            FilterArg::Bilinear => Filter::Bilinear,
        },
        subspan: args.subspan,
        textures: true,
        dither: args.dither,
        fixed_vertices: args.fixed_vertices,
        // Without a depth buffer the nearest triangle must be drawn last.
        order: if args.depth == DepthKind::None { DrawOrder::BackToFront } else { DrawOrder::AsStored },
        wire_color: matches!(args.mode, ModeArg::SolidWire).then_some([255, 255, 0]),
        // The scene's or the arguments' (see `fog`), which need the model.
        fog: None,
    }
}

/// What is wrong with a camera at `eye` looking at `target` with `up`, in the options' words.
pub(crate) fn camera_error(e: soft3d::CameraError, (eye, target, up): (Vec3, Vec3, Vec3)) -> String {
    if e == soft3d::CameraError::BadLookAt && eye != target && up != Vec3::ZERO {
        let along = (target - eye).normalize().cross(up.normalize()).length() < 1e-6;
        if along {
            return format!(
                "camera: it looks along its up direction {:?} (--up, default 0,1,0): give another --up, e.g. --up 0,0,1",
                up.to_array()
            );
        }
    }
    if e == soft3d::CameraError::BadLookAt && up == Vec3::ZERO {
        return "--up: must not be zero".to_string();
    }
    e.to_string()
}
