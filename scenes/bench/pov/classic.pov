// POV-Ray 3.7 equivalent of scenes/bench/classic.scene, for `cargo xtask bench` comparisons.
// Same camera, light, objects and recursion depth; no anti-aliasing; no radiosity.
// POV-Ray is left-handed and whitted right-handed, so whitted.scene has every x negated:
// the two images match.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 5 adc_bailout 0.001 ambient_light rgb 1 }
background { rgb <0.10, 0.30, 0.75> }
// Vertical field of view 45 degrees at 4:3 is 57.82 degrees horizontally.
camera { perspective location <0, 1.6, -6.5> look_at <0, 1, 0> right x*4/3 up y angle 57.82 }
light_source { <6, 10, -8> rgb 1 }
plane { y, 0
  texture { pigment { checker rgb <0.9, 0.1, 0.1>, rgb <0.95, 0.9, 0.2> scale 1 }
            finish { ambient 0.1 diffuse 1 specular 0 } } }
sphere { <0.75, 1.1, -1.2>, 1.0
  texture { pigment { rgbf <1, 1, 1, 0.9> }
            finish { ambient 0 diffuse 0.05 phong 0.8 phong_size 200 reflection 0.1 } }
  interior { ior 1.5 } }
sphere { <-1.2, 1.0, 1.4>, 1.0
  texture { pigment { rgb 0.2 } finish { ambient 0.05 diffuse 0.1 phong 0.8 phong_size 120 reflection 0.8 } } }
