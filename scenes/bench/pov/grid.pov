// POV-Ray 3.7 equivalent of scenes/bench/grid.scene with N = 1000 (1,000,000 spheres): same
// camera, lights, floor and spheres (x negated: POV-Ray is left-handed, whitted right-handed).
#version 3.7;
#declare N = 1000;
#declare Half = (N - 1) / 2;
global_settings { assumed_gamma 1.0 max_trace_level 5 adc_bailout 0.001 ambient_light rgb 1 }
background { rgb 0 }
// Vertical field of view 50 degrees at 4:3 is 63.59 degrees horizontally.
camera { perspective location <0, N * 0.8, -N * 0.9> look_at <0, 0, 0> right x*4/3 up y angle 63.59 }
light_source { <-N, 2 * N, -N> rgb 1 }
light_source { <0, 0, 0> rgb 0.3 parallel point_at <-1, -1, 1> }
plane { y, -0.5 texture { pigment { checker rgb 1, rgb 0.0513 scale 2 } finish { ambient 0.1 diffuse 0.8 } } }
#declare Matte = texture { pigment { rgb <0.8, 0.3, 0.2> } finish { ambient 0.1 diffuse 1 phong 0.3 phong_size 40 } }
#for (I, 0, N - 1)
  #for (J, 0, N - 1)
    sphere { <Half - I, 0, J - Half>, 0.4 texture { Matte } }
  #end
#end
