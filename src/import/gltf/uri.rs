//! A buffer's `uri` as the JSON is read: a `data:` URI is decoded on the spot, straight from the JSON text (a `.gltf`
//! file's base64 buffer is most of its text, which is then never copied as a string); any other URI is kept to be
//! followed when the buffer is needed (`buffers.rs`).

use std::fmt;

use base64::Engine as _;
use base64::engine::DecodePaddingMode;
use base64::engine::general_purpose::{GeneralPurpose, GeneralPurposeConfig};
use serde::Deserialize;
use serde::de::{self, Deserializer, Visitor};

/// Base64 as glTF writers produce it; some leave out the `=` padding.
const BASE64: GeneralPurpose = GeneralPurpose::new(
    &base64::alphabet::STANDARD,
    GeneralPurposeConfig::new().with_decode_padding_mode(DecodePaddingMode::Indifferent),
);

/// A buffer's `uri`.
#[derive(Debug)]
pub(super) enum Uri {
    /// The bytes of a `data:` URI, or why they cannot be had (said only if the buffer is needed).
    Data(std::result::Result<Vec<u8>, String>),
    /// A file, by its URI reference.
    Reference(String),
}

impl<'de> Deserialize<'de> for Uri {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> std::result::Result<Self, D::Error> {
        struct UriVisitor;

        impl Visitor<'_> for UriVisitor {
            type Value = Uri;

            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a URI")
            }

            fn visit_str<E: de::Error>(self, uri: &str) -> std::result::Result<Uri, E> {
                Ok(match strip_prefix_ignore_case(uri, "data:") {
                    Some(data) => Uri::Data(decode_data_uri(data)),
                    None => Uri::Reference(uri.to_owned()),
                })
            }
        }

        deserializer.deserialize_str(UriVisitor)
    }
}

/// The payload of `data:[<media type>];base64,<payload>` (glTF buffers are always base64).
fn decode_data_uri(after_scheme: &str) -> std::result::Result<Vec<u8>, String> {
    let Some((header, payload)) = after_scheme.split_once(',') else {
        return Err("malformed data URI (no comma)".into());
    };
    if !header.to_ascii_lowercase().ends_with(";base64") {
        return Err(format!("data URI `data:{header},…` is not base64"));
    }
    BASE64.decode(payload).map_err(|e| format!("bad base64 in data URI: {e}"))
}

fn strip_prefix_ignore_case<'a>(s: &'a str, prefix: &str) -> Option<&'a str> {
    let head = s.get(..prefix.len())?;
    head.eq_ignore_ascii_case(prefix).then(|| &s[prefix.len()..])
}

#[cfg(test)]
mod tests {
    use base64::engine::general_purpose;

    use super::*;

    #[test]
    fn data_uris_decode_with_or_without_padding() {
        assert_eq!(decode_data_uri("application/octet-stream;base64,AQID"), Ok(vec![1, 2, 3]));
        assert_eq!(decode_data_uri("application/gltf-buffer;base64,AQI"), Ok(vec![1, 2]));
        assert!(decode_data_uri("text/plain,hello").is_err());
        assert!(decode_data_uri("application/octet-stream;base64,@@@@").is_err());
        let encoded = general_purpose::STANDARD.encode([9u8; 10]);
        assert_eq!(decode_data_uri(&format!(";base64,{encoded}")), Ok(vec![9; 10]));
    }
}
