//! A scan as JUnit XML, the report CI systems show (GitLab, Jenkins, Azure DevOps, GitHub test reporters): one test
//! suite per file, one test case per clip, a failure per stretched bone (its worst shear and when), and a file that
//! could not be loaded as an error.

use std::io;

use quick_xml::Writer;
use quick_xml::events::{BytesDecl, BytesText, Event};

use crate::analysis::report::{AnimationInfo, AnimationScan, FileScan};

/// The JUnit XML of `files`.
pub fn junit(files: &[FileScan]) -> String {
    let mut writer = Writer::new_with_indent(Vec::new(), b' ', 2);
    write(&mut writer, files).expect("writing to memory does not fail");
    String::from_utf8(writer.into_inner()).expect("quick-xml writes UTF-8")
}

/// Counts of one suite or of all: test cases, failed ones, errors.
#[derive(Clone, Copy, Default)]
struct Counts {
    tests: usize,
    failures: usize,
    errors: usize,
}

impl Counts {
    fn of(file: &FileScan) -> Self {
        match file.error {
            Some(_) => Counts { tests: 1, failures: 0, errors: 1 },
            None => Counts {
                tests: file.animations.len(),
                failures: file.animations.iter().filter(|a| !a.stretched.is_empty()).count(),
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

fn write(writer: &mut Writer<Vec<u8>>, files: &[FileScan]) -> io::Result<()> {
    writer.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None)))?;
    let total = files.iter().map(Counts::of).fold(Counts::default(), Counts::add);
    let attributes = total.attributes();
    let suites = writer
        .create_element("testsuites")
        .with_attribute(("name", "bonescope scan"))
        .with_attributes(attributes.iter().map(|(k, v)| (*k, v.as_str())));
    suites.write_inner_content(|writer| files.iter().try_for_each(|file| suite(writer, file)))?;
    Ok(())
}

fn suite(writer: &mut Writer<Vec<u8>>, file: &FileScan) -> io::Result<()> {
    let attributes = Counts::of(file).attributes();
    let element = writer
        .create_element("testsuite")
        .with_attribute(("name", file.file.as_str()))
        .with_attributes(attributes.iter().map(|(k, v)| (*k, v.as_str())));
    element.write_inner_content(|writer| match &file.error {
        Some(error) => {
            let case = writer
                .create_element("testcase")
                .with_attributes([("classname", file.file.as_str()), ("name", "load")]);
            case.write_inner_content(|writer| {
                let problem =
                    writer.create_element("error").with_attributes([("message", error.as_str()), ("type", "load")]);
                problem.write_text_content(BytesText::new(error))?;
                Ok(())
            })?;
            Ok(())
        }
        None => file.animations.iter().try_for_each(|clip| case(writer, &file.file, clip)),
    })?;
    Ok(())
}

fn case(writer: &mut Writer<Vec<u8>>, file: &str, clip: &AnimationScan) -> io::Result<()> {
    let name = format!("{} (inherit {})", AnimationInfo::describe(clip.animation.as_ref()), clip.inherit);
    let element = writer.create_element("testcase").with_attributes([("classname", file), ("name", name.as_str())]);
    if clip.stretched.is_empty() {
        element.write_empty()?;
        return Ok(());
    }
    element.write_inner_content(|writer| {
        for bone in &clip.stretched {
            let summary = &bone.summary;
            let message = format!(
                "`{}` stretched: worst shear {:.2}° at {:.3} s",
                bone.name, summary.worst_shear_deg, summary.worst_shear_time
            );
            let details = format!(
                "{} of {} samples flagged, first at {:.3} s; worst stretch angle {:.2}°",
                summary.flagged_samples,
                clip.samples,
                summary.first_flagged_time.unwrap_or_default(),
                summary.worst_stretch_deg
            );
            let failure = writer
                .create_element("failure")
                .with_attributes([("message", message.as_str()), ("type", "stretched")]);
            failure.write_text_content(BytesText::new(&details))?;
        }
        Ok(())
    })?;
    Ok(())
}
