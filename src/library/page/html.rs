//! The HTML page: one self-contained file (its style, script and pictures inline) that opens offline from a CI
//! artifact. Written with maud: the markup is checked when bonescope is compiled and every text is escaped.

use maud::{DOCTYPE, Markup, PreEscaped, html};

use super::svg::{colour_of_degrees, figure, sparkline};
use super::{Overview, Row, What, clip_label, count, time_text};
use crate::analysis::report::{AnimationScan, BoneScanReport};

/// How many of a clip's stretched bones are listed open; the rest are folded under a summary.
const BONES_SHOWN: usize = 4;

/// The pictures' sizes, pixels.
const FIGURE_PX: u32 = 120;
const SPARK_WIDTH: u32 = 120;
const SPARK_HEIGHT: u32 = 22;

/// The page of `overview`, titled `title`. Where something is wrong (a stretched bone or a refused file), the page
/// opens on those rows alone, the clean clips written hidden ("stretched only", one click away): what the lead came
/// for is on top, and a library's clean thousand rows are not laid out before the page shows.
pub fn html(overview: &Overview, title: &str) -> String {
    let problems_only = overview.rows.iter().any(|row| row.worst_shear_deg().is_none_or(|worst| worst > 0.0));
    let page = html! {
        (DOCTYPE)
        html lang="en" {
            head {
                meta charset="utf-8";
                meta name="viewport" content="width=device-width, initial-scale=1";
                title { (title) }
                style { (PreEscaped(STYLE)) }
            }
            body {
                h1 { (title) }
                p #summary .verdict[overview.verdict.exit_status() != 0] { (overview.summary()) }
                div .controls {
                    label { "Filter " input #filter type="search" placeholder="file, clip or bone"; }
                    label { input #stretched type="checkbox" checked[problems_only]; " stretched only" }
                    label { "Sort by "
                        select #sort {
                            option value="worst" { "worst shear (refused first)" }
                            option value="file" { "file" }
                            option value="format" { "format" }
                        }
                    }
                    span #shown {}
                    (legend())
                }
                table #clips {
                    thead { tr {
                        th data-sort="worst" { "worst shear" }
                        th data-sort="file" { "file" }
                        th { "clip" }
                        th data-sort="format" { "format" }
                        th { "worst moment" }
                        th { "stretched bones" }
                    } }
                    tbody { @for row in &overview.rows { (row_markup(row, problems_only)) } }
                }
                script { (PreEscaped(SCRIPT)) }
            }
        }
    };
    page.into_string()
}

/// One row; a clean clip's hidden where the page opens on the problems alone (`problems_only`).
fn row_markup(row: &Row, problems_only: bool) -> Markup {
    let worst = row.worst_shear_deg();
    let data_worst = worst.map_or_else(|| "Infinity".to_owned(), |w| w.to_string());
    match row.what {
        What::Refused(error) => html! {
            tr .refused data-worst=(data_worst) data-file=(row.file) data-format=(row.format)
                data-search=(format!("{} {error}", row.file).to_lowercase()) {
                td .num { "refused" }
                td .file { (row.file) }
                td colspan="4" .error { (crate::import::text::printable(error)) }
            }
        },
        What::Clip(clip) => html! {
            tr hidden[problems_only && worst == Some(0.0)] data-worst=(data_worst) data-file=(row.file)
                data-format=(row.format) data-search=(search_text(row, clip)) {
                td .num { (format!("{:.3}°", worst.unwrap_or(0.0))) }
                td .file { (row.file) }
                td { (clip_label(clip)) br; span .small { (clip_span(clip)) } }
                td { (row.format) }
                td .picture { (worst_moment(clip)) }
                td { (stretched_bones(clip)) }
            }
        },
    }
}

/// What a filter matches a clip's row by: the file, the clip and its stretched bones.
fn search_text(row: &Row, clip: &AnimationScan) -> String {
    let bones: Vec<&str> = clip.stretched.iter().map(|b| b.name.as_str()).collect();
    format!("{} {} {}", row.file, clip_label(clip), bones.join(" ")).to_lowercase()
}

/// "2.000 s from 0.0333 s, 30 fps".
fn clip_span(clip: &AnimationScan) -> String {
    match &clip.animation {
        Some(info) => format!("{:.3} s from {:.4} s, {} fps", info.duration, info.start, info.frame_rate),
        None => String::new(),
    }
}

/// The figure at the clip's worst moment, the worst bone named under it; nothing where no bone stretches.
fn worst_moment(clip: &AnimationScan) -> Markup {
    match (&clip.sketch, clip.stretched.first()) {
        (Some(sketch), Some(worst)) => html! {
            (figure(sketch, &worst.name, FIGURE_PX))
            div .small { (worst.name) " at " (time_text(clip, sketch.time)) }
        },
        _ => html! { span .none { "no shear" } },
    }
}

/// Each stretched bone, the worst [`BONES_SHOWN`] open and the rest folded.
fn stretched_bones(clip: &AnimationScan) -> Markup {
    let (shown, folded) = clip.stretched.split_at(clip.stretched.len().min(BONES_SHOWN));
    html! {
        @if clip.stretched.is_empty() {
            span .none { "none" }
            @if !clip.non_uniform.is_empty() { div .small { "non-uniform (aligned): " (clip.non_uniform.join(", ")) } }
        }
        @for (i, bone) in shown.iter().enumerate() { (bone_block(clip, i, bone)) }
        @if !folded.is_empty() {
            details {
                summary { (count(folded.len(), "more stretched bone", "more stretched bones")) }
                @for (i, bone) in folded.iter().enumerate() { (bone_block(clip, BONES_SHOWN + i, bone)) }
            }
        }
    }
}

/// One stretched bone (the `i`th, worst first): its curve, its worst shear, when, how often flagged; with
/// `--explain`, its cause and fix.
fn bone_block(clip: &AnimationScan, i: usize, bone: &BoneScanReport) -> Markup {
    let curve = clip.sketch.as_ref().and_then(|s| s.curves.get(i));
    html! {
        div .bone {
            @if let Some(curve) = curve { (sparkline(curve, SPARK_WIDTH, SPARK_HEIGHT)) }
            div {
                (bone_line(clip, bone))
                @if let Some(explained) = clip.explained.iter().find(|e| e.name == bone.name) {
                    div .why { (explained.line) }
                    @if !explained.answers.is_empty() {
                        details .why {
                            summary { "to play it as authored, to remove it" }
                            @for answer in &explained.answers { div { (answer) } }
                        }
                    }
                }
            }
        }
    }
}

/// The shear colours' key: the ramp from 0.1° to 10°, as the app draws it.
fn legend() -> Markup {
    let stops: Vec<String> = [0.1, 1.0, 10.0].iter().map(|&deg| colour_of_degrees(deg)).collect();
    let ramp = format!("background: linear-gradient(to right, {})", stops.join(", "));
    html! {
        span .legend title="a stretched bone's colour by its shear (others grey), as in the app" {
            "shear " span .ramp style=(ramp) {} " 0.1° · 1° · 10°+"
        }
    }
}

/// "forearm 18.666° at 0.5539 s (frame 16.6), flagged 119/121".
fn bone_line(clip: &AnimationScan, bone: &BoneScanReport) -> Markup {
    let s = &bone.summary;
    html! {
        b { (bone.name) } " " span .num { (format!("{:.3}°", s.worst_shear_deg)) } " at "
        (time_text(clip, s.worst_shear_time)) span .small { (format!(", flagged {}/{}", s.flagged_samples, clip.samples)) }
    }
}

const STYLE: &str = r#"
body { font: 14px/1.4 system-ui, sans-serif; margin: 1.5em; color: #1d1f23; background: #fafafa; }
h1 { font-size: 1.4em; margin: 0 0 .3em; }
#summary { font-size: 1.05em; padding: .5em .8em; background: #e9f5ec; border-left: 4px solid #3a9a5b; }
#summary.verdict { background: #fbe9ed; border-left-color: #eb4064; }
.controls { display: flex; gap: 1.5em; align-items: center; margin: 1em 0; flex-wrap: wrap; }
.controls input[type=search] { width: 18em; }
table { border-collapse: collapse; width: 100%; background: #fff; }
th { text-align: left; background: #eceef1; position: sticky; top: 0; padding: .4em .6em; }
th[data-sort] { cursor: pointer; text-decoration: underline dotted; }
td { border-top: 1px solid #e2e4e8; padding: .4em .6em; vertical-align: top; }
td.num, .num { font-variant-numeric: tabular-nums; white-space: nowrap; }
td.file { word-break: break-all; max-width: 22em; }
tr.refused td { background: #fff4f0; }
.error { color: #a02a16; font-family: ui-monospace, monospace; font-size: .9em; }
.small { color: #5d636d; font-size: .85em; }
.none { color: #8a8f98; }
.bone { display: flex; gap: .6em; align-items: flex-start; margin-bottom: .3em; }
.bone svg { flex: none; margin-top: .1em; }
details summary { cursor: pointer; color: #5d636d; font-size: .85em; }
.legend { margin-left: auto; color: #5d636d; font-size: .85em; }
.ramp { display: inline-block; width: 6em; height: .8em; vertical-align: middle; border-radius: 2px; }
.why { color: #3d434d; font-size: .85em; margin-left: 1em; }
"#;

const SCRIPT: &str = r#"
(() => {
  const body = document.querySelector('#clips tbody');
  const rows = Array.from(body.rows);
  const filter = document.getElementById('filter');
  const stretched = document.getElementById('stretched');
  const sort = document.getElementById('sort');
  const shown = document.getElementById('shown');
  const keys = {
    worst: r => [-parseFloat(r.dataset.worst), r.dataset.file],
    file: r => [r.dataset.file, -parseFloat(r.dataset.worst)],
    format: r => [r.dataset.format, r.dataset.file],
  };
  const compare = (a, b) => a[0] < b[0] ? -1 : a[0] > b[0] ? 1 : a[1] < b[1] ? -1 : a[1] > b[1] ? 1 : 0;
  function order(key) {
    const of = keys[key] || keys.worst;
    rows.sort((a, b) => compare(of(a), of(b)));
    rows.forEach(r => body.appendChild(r));
    sort.value = key in keys ? key : 'worst';
  }
  function apply() {
    const text = filter.value.trim().toLowerCase();
    let count = 0;
    for (const r of rows) {
      const hide = (text && !r.dataset.search.includes(text)) || (stretched.checked && parseFloat(r.dataset.worst) === 0);
      r.hidden = hide;
      if (!hide) count++;
    }
    shown.textContent = count + ' of ' + rows.length + ' rows';
  }
  const asked = new URLSearchParams(location.hash.slice(1));
  filter.value = asked.get('filter') || '';
  if (asked.has('stretched')) stretched.checked = asked.get('stretched') === '1';
  order(asked.get('sort') || 'worst');
  apply();
  filter.addEventListener('input', apply);
  stretched.addEventListener('change', apply);
  sort.addEventListener('change', () => order(sort.value));
  document.querySelectorAll('th[data-sort]').forEach(th => th.addEventListener('click', () => order(th.dataset.sort)));
})();
"#;
