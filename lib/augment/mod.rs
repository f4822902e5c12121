//! Skeletal augmentation (AnyTop §3.3, appendix C): work in progress.
