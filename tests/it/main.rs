//! All integration tests in one harness (one binary to build and link instead of one per file).
//! Run one module with `cargo test --test it <module>::`.

mod adversarial;
mod anytop_repr;
mod auto_binding;
mod bvh_corpus;
mod common;
mod fk_reference;
mod generated_docs;
mod gltf_io;
mod help_examples;
mod latent_cli;
mod malformed;
mod metrics_corpus;
mod metrics_fid_numpy;
mod mo_dift_cli;
mod mo_edit;
mod mo_encode_anytop;
mod mo_encode_m2m;
mod mo_metrics_cli;
mod mo_render_cli;
mod mo_retarget_cli;
mod mo_sample_edit;
mod mo_sample_examples;
mod mo_segment_cli;
mod mo_train_cli;
mod mo_train_sample_cli;
mod name_embeddings;
mod npy;
mod ood;
mod post_process;
mod render_html;
mod skel_aug;
mod skel_info_cli;
mod topology_reference;
