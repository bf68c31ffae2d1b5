"""The modules that wavepath's tools share (imported, never run): accuracy_lib (PFM, references,
error statistics), closed_form (closed-form reference images), peers_scene (the glTF converter
for peer renderers), stage_names (the stage kernels, read from host/render/pipeline.h) and
system_python (re-running under Debian's python3 when numpy is missing)."""
