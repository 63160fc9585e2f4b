// Fragment counting switched off: the hooks every tree's fragment stage calls are empty (see
// count_on.wgsl), so the frame's pipelines carry no counting code and no extra bind group.

fn count_enter(pos: vec4<f32>) {}

fn count_shown(pos: vec4<f32>, alpha: f32) {}

fn count_depth(pos: vec4<f32>) {}
