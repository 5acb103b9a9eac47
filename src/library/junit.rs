//! A scan as JUnit XML, the report CI systems show (GitLab, Jenkins, Azure DevOps, GitHub test reporters): one test
//! suite per file, one test case per clip, a failure per stretched bone (its worst shear and when, and with
//! `scan --explain` its cause and cheapest fix), and a file that could not be loaded as an error. Reports that judge
//! nothing (`scan --compare-inherit`, `storage`) give passing cases with their table as the case's output.

use std::borrow::Cow;
use std::io;

use quick_xml::Writer;
use quick_xml::events::{BytesDecl, BytesText, Event};

use crate::analysis::report::{AnimationInfo, AnimationScan, FileReport, FileScan};

/// One clip as a JUnit test case: its name, its failures (message and details), and text for its `system-out`.
pub struct Case {
    pub name: String,
    pub failures: Vec<(String, String)>,
    pub output: Option<String>,
}

/// The JUnit XML of a stretch scan: a failure per stretched bone.
pub fn junit(files: &[FileScan]) -> String {
    junit_of(files, |_, clip| stretch_case(clip))
}

/// The JUnit XML of any scan's `files`, each clip made a test case by `case` (given the file's name and the clip).
pub fn junit_of<T>(files: &[FileReport<T>], case: impl Fn(&str, &T) -> Case) -> String {
    let suites: Vec<Suite> = files
        .iter()
        .map(|file| Suite {
            name: xml_text(&file.file),
            error: file.error.as_deref().map(xml_text),
            cases: file.animations.iter().map(|clip| xml_case(case(&file.file, clip))).collect(),
        })
        .collect();
    let mut writer = Writer::new_with_indent(Vec::new(), b' ', 2);
    write(&mut writer, &suites).expect("writing to memory does not fail");
    String::from_utf8(writer.into_inner()).expect("quick-xml writes UTF-8")
}

/// Text XML 1.0 can hold: the control characters it forbids (all but tab, line feed and carriage return, which
/// tables in `system-out` use) escaped as `\x1b`. Reports read back by `report` may come from anywhere.
fn xml_text(text: &str) -> Cow<'_, str> {
    let forbidden = |c: char| c.is_control() && !matches!(c, '\t' | '\n' | '\r');
    if !text.chars().any(forbidden) {
        return Cow::Borrowed(text);
    }
    let escape = |c: char| {
        if forbidden(c) { crate::import::text::printable(&c.to_string()).into_owned() } else { c.to_string() }
    };
    Cow::Owned(text.chars().map(escape).collect())
}

/// A case whose texts XML can hold ([`xml_text`]).
fn xml_case(case: Case) -> Case {
    let own = |text: &str| xml_text(text).into_owned();
    Case {
        name: own(&case.name),
        failures: case.failures.iter().map(|(message, details)| (own(message), own(details))).collect(),
        output: case.output.as_deref().map(own),
    }
}

/// One file: its clips' cases, or the error that kept it from loading.
struct Suite<'a> {
    name: Cow<'a, str>,
    error: Option<Cow<'a, str>>,
    cases: Vec<Case>,
}

/// Counts of one suite or of all: test cases, failed ones, errors.
#[derive(Clone, Copy, Default)]
struct Counts {
    tests: usize,
    failures: usize,
    errors: usize,
}

impl Counts {
    fn of(suite: &Suite) -> Self {
        match suite.error {
            Some(_) => Counts { tests: 1, failures: 0, errors: 1 },
            None => Counts {
                tests: suite.cases.len(),
                failures: suite.cases.iter().filter(|c| !c.failures.is_empty()).count(),
                errors: 0,
            },
        }
    }

    fn add(self, other: Counts) -> Self {
        Counts {
            tests: self.tests + other.tests,
            failures: self.failures + other.failures,
            errors: self.errors + other.errors,
        }
    }

    fn attributes(&self) -> [(&'static str, String); 3] {
        [
            ("tests", self.tests.to_string()),
            ("failures", self.failures.to_string()),
            ("errors", self.errors.to_string()),
        ]
    }
}

fn write(writer: &mut Writer<Vec<u8>>, suites: &[Suite]) -> io::Result<()> {
    writer.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None)))?;
    let total = suites.iter().map(Counts::of).fold(Counts::default(), Counts::add);
    let attributes = total.attributes();
    let element = writer
        .create_element("testsuites")
        .with_attribute(("name", "bonescope scan"))
        .with_attributes(attributes.iter().map(|(k, v)| (*k, v.as_str())));
    element.write_inner_content(|writer| suites.iter().try_for_each(|suite| write_suite(writer, suite)))?;
    Ok(())
}

fn write_suite(writer: &mut Writer<Vec<u8>>, suite: &Suite) -> io::Result<()> {
    let attributes = Counts::of(suite).attributes();
    let element = writer
        .create_element("testsuite")
        .with_attribute(("name", suite.name.as_ref()))
        .with_attributes(attributes.iter().map(|(k, v)| (*k, v.as_str())));
    element.write_inner_content(|writer| match suite.error.as_deref() {
        Some(error) => {
            let case = writer
                .create_element("testcase")
                .with_attributes([("classname", suite.name.as_ref()), ("name", "load")]);
            case.write_inner_content(|writer| {
                let problem = writer.create_element("error").with_attributes([("message", error), ("type", "load")]);
                problem.write_text_content(BytesText::new(error))?;
                Ok(())
            })?;
            Ok(())
        }
        None => suite.cases.iter().try_for_each(|case| write_case(writer, &suite.name, case)),
    })?;
    Ok(())
}

fn write_case(writer: &mut Writer<Vec<u8>>, file: &str, case: &Case) -> io::Result<()> {
    let element =
        writer.create_element("testcase").with_attributes([("classname", file), ("name", case.name.as_str())]);
    if case.failures.is_empty() && case.output.is_none() {
        element.write_empty()?;
        return Ok(());
    }
    element.write_inner_content(|writer| {
        for (message, details) in &case.failures {
            let failure = writer
                .create_element("failure")
                .with_attributes([("message", message.as_str()), ("type", "stretched")]);
            failure.write_text_content(BytesText::new(details))?;
        }
        if let Some(output) = &case.output {
            writer.create_element("system-out").write_text_content(BytesText::new(output))?;
        }
        Ok(())
    })?;
    Ok(())
}

/// A clip of a stretch scan: a failure per stretched bone, with its worst shear and when.
fn stretch_case(clip: &AnimationScan) -> Case {
    let name = format!("{} (inherit {})", AnimationInfo::describe(clip.animation.as_ref()), clip.inherit);
    let failures = clip
        .stretched
        .iter()
        .map(|bone| {
            let summary = &bone.summary;
            let message = format!(
                "`{}` stretched: worst shear {:.2}° at {:.3} s",
                bone.name, summary.worst_shear_deg, summary.worst_shear_time
            );
            let mut details = format!(
                "{} of {} samples flagged, first at {:.3} s; worst stretch angle {:.2}°",
                summary.flagged_samples,
                clip.samples,
                summary.first_flagged_time.unwrap_or_default(),
                summary.worst_stretch_deg
            );
            // With `scan --explain`: whose scale does it, and the cheapest fix.
            if let Some(why) = clip.explained.iter().find(|e| e.name == bone.name) {
                details.push_str(&format!("\nwhy: {}", why.line));
            }
            (message, details)
        })
        .collect();
    Case { name, failures, output: None }
}

#[cfg(test)]
mod tests {
    use quick_xml::events::Event;

    use super::*;

    #[test]
    fn control_characters_are_escaped_so_the_report_parses() {
        let file = FileScan {
            file: "evil\u{1b}]0;title\u{7}.glb".to_owned(),
            error: Some("nodes[0]: bad \u{0}name\nwith a break".to_owned()),
            animations: Vec::new(),
        };
        let xml = junit(&[file]);
        let mut reader = quick_xml::Reader::from_str(&xml);
        let mut texts = Vec::new();
        loop {
            match reader.read_event().expect("the report is XML 1.0") {
                Event::Eof => break,
                Event::Text(text) if !text.decode().unwrap().trim().is_empty() => {
                    texts.push(text.decode().unwrap().into_owned());
                }
                Event::Start(element) | Event::Empty(element) if element.name().as_ref() == b"testsuite" => {
                    let name = element.try_get_attribute("name").unwrap().unwrap();
                    let name = name.normalized_value(quick_xml::XmlVersion::Explicit1_0).unwrap();
                    assert_eq!(name, "evil\\x1b]0;title\\x07.glb");
                }
                _ => {}
            }
        }
        assert_eq!(texts, ["nodes[0]: bad \\x00name\nwith a break"], "line breaks are XML; NUL is not");
    }
}
