//! `render`'s command and what it writes: PNG, raw framebuffer or GIF, and the statistics.

use super::*;

pub(crate) fn cmd_render(args: &RenderArgs) -> Result<()> {
    // Checked before any work: a picture written under another format's name would mislead.
    let kind = output_kind(&args.output)?;
    let mut conv = args.conv.clone();
    // Keep 8-bit texels when rendering to RGB888 so the output compares exactly with others.
    if args.format == PixelFormat::Rgb888
        && matches!(conv.texture_format, TexFormat::Auto)
        && args.input.extension().is_none_or(|e| e != "s3d")
    {
        conv.texture_format = TexFormat::Rgba8888;
    }
    let bytes = load_scene(&args.input, &conv)?;
    let model = Model::parse(&bytes).map_err(|e| format!("{}: {e}", args.input.display()))?;
    let view = make_view(args, &model)?;
    if kind == OutputKind::Gif {
        return write_gif(&args.output, &model, &view, args);
    }
    let start = std::time::Instant::now();
    let frame = render_any(&model, &view, 0.0, args, kind == OutputKind::Raw)?;
    let elapsed = start.elapsed();
    let bytes = match kind {
        OutputKind::Raw => frame.raw,
        _ => encode_png(&frame.rgb, view.width, view.height)?,
    };
    write_atomically(&args.output, &bytes)?;
    print_stats(args, (1, &view), (&model, &frame.stats), elapsed.as_secs_f64() * 1e3);
    if let Some(gif) = &args.gif {
        write_gif(gif, &model, &view, args)?;
    }
    Ok(())
}

pub(crate) fn encode_png(rgb: &[[u8; 3]], w: u16, h: u16) -> Result<Vec<u8>> {
    let flat: Vec<u8> = rgb.iter().flatten().copied().collect();
    let img = image::RgbImage::from_raw(w as u32, h as u32, flat).ok_or("image size mismatch")?;
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).map_err(|e| e.to_string())?;
    Ok(out.into_inner())
}

/// Prints frame `frame`'s statistics as `--stats` asks: a line of `name value` pairs after the
/// output's name, or a JSON object. The same fields either way: the firmware's (examples/qemu)
/// that a host render knows, summed over the frame's bands (`drawn` counts a triangle once for
/// each band it has pixels in, as the firmware does), and the time it took.
pub(crate) fn print_stats(
    args: &RenderArgs,
    (frame, view): (u32, &View),
    (model, stats): (&Model<'_>, &Stats),
    ms: f64,
) {
    let fields = [
        ("frame", u64::from(frame)),
        ("width", u64::from(view.width)),
        ("height", u64::from(view.height)),
        ("bands", u64::from(view.bands)),
        ("threads", u64::from(view.threads)),
        ("triangles", model.draw_counts().0 as u64),
        ("drawn", u64::from(stats.drawn)),
        ("pixels_written", u64::from(stats.pixels_written)),
        ("runs", u64::from(stats.runs)),
        ("depth_rejected", u64::from(stats.depth_rejected)),
        ("culled_back_face", u64::from(stats.culled_back_face)),
        ("culled_frustum", u64::from(stats.culled_frustum) + u64::from(stats.culled_frustum_mesh)),
        ("clipped", u64::from(stats.clipped)),
    ];
    match args.stats {
        StatsFormat::Text => {
            let pairs: Vec<String> = fields.iter().map(|(name, value)| format!("{name} {value}")).collect();
            println!("{}: {}, {ms:.2} ms", args.output.display(), pairs.join(", "));
        }
        StatsFormat::Json => {
            let mut object: serde_json::Map<String, serde_json::Value> =
                fields.iter().map(|&(name, value)| (name.to_string(), value.into())).collect();
            object.insert("ms".into(), ms.into());
            println!("{}", serde_json::Value::Object(object));
        }
    }
}

/// What a GIF shows: the scene's animation (every frame of a group's range, at its frame
/// rate: `--animation`'s group, else every group over all their ranges), or without one a
/// turntable of `--frames` frames at 20 a second.
struct Playback {
    frames: u32,
    delay_ms: u32,
    /// `(first frame, group)` of an animation; `None`: a turntable.
    animation: Option<(f32, Option<usize>)>,
}

/// At most this many frames of an animation in a GIF.
const MAX_GIF_FRAMES: u32 = 600;

fn playback(model: &Model<'_>, view: &View, args: &RenderArgs) -> Playback {
    let turntable = Playback { frames: args.frames, delay_ms: 50, animation: None };
    let Some(a) = model.animation().filter(|a| a.group_count() > 0) else { return turntable };
    let group = view.pose.and_then(|(_, g)| g);
    let groups: Vec<_> = group.map_or(0..a.group_count(), |g| g..g + 1).filter_map(|g| a.group(g)).collect();
    let from = groups.iter().map(|g| g.range().0).fold(f32::INFINITY, f32::min);
    let to = groups.iter().map(|g| g.range().1).fold(f32::NEG_INFINITY, f32::max);
    let fps = groups.iter().flat_map(|g| g.tracks()).find_map(|t| a.track(t)).map_or(30.0, |t| t.fps());
    let frames = ((to - from).max(0.0) as u32 + 1).min(MAX_GIF_FRAMES);
    // A GIF's delay is whole hundredths of a second, and browsers play one under 2 (20 ms) at
    // 100 ms: a 60 fps animation is played at 50 frames a second rather than at 10.
    Playback { frames, delay_ms: (1000.0 / fps).round().max(20.0) as u32, animation: Some((from, group)) }
}

pub(crate) fn write_gif(path: &Path, model: &Model<'_>, view: &View, args: &RenderArgs) -> Result<()> {
    let mut out = Vec::new();
    let play = playback(model, view, args);
    {
        let mut enc = image::codecs::gif::GifEncoder::new_with_speed(&mut out, 10);
        enc.set_repeat(image::codecs::gif::Repeat::Infinite).map_err(|e| e.to_string())?;
        let frames = play.frames;
        for f in 0..frames {
            let mut posed = view.clone();
            let spin = match play.animation {
                Some((first, group)) => {
                    posed.pose = Some((first + f as f32, group));
                    0.0
                }
                None => f as f32 / frames as f32 * std::f32::consts::TAU,
            };
            let start = std::time::Instant::now();
            let frame = render_any(model, &posed, spin, args, false)?;
            if args.stats == StatsFormat::Json {
                print_stats(args, (f + 1, view), (model, &frame.stats), start.elapsed().as_secs_f64() * 1e3);
            }
            let rgba: Vec<u8> = frame.rgb.iter().flat_map(|c| [c[0], c[1], c[2], 255]).collect();
            let img =
                image::RgbaImage::from_raw(view.width as u32, view.height as u32, rgba).ok_or("image size mismatch")?;
            let frame = image::Frame::from_parts(img, 0, 0, image::Delay::from_numer_denom_ms(play.delay_ms, 1));
            enc.encode_frame(frame).map_err(|e| e.to_string())?;
        }
    }
    write_atomically(path, &out)?;
    let what = if play.animation.is_some() { "of the scene's animation" } else { "of a turntable" };
    println!("{}: {} frames {what}", path.display(), play.frames);
    Ok(())
}
