//! Feature encodings of a Motion: work in progress.
