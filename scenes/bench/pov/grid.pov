// POV-Ray 3.7 equivalent of scenes/bench/grid.scene: an N x N grid of spheres (N=1000 by
// default, +D-free: edit N), seen from above, one light, shadows.
#version 3.7;
#declare N = 1000;
global_settings { assumed_gamma 1.0 max_trace_level 5 adc_bailout 0.001 ambient_light rgb 1 }
background { rgb <0.05, 0.05, 0.1> }
camera { perspective location <N/2, N*0.6, -N*0.35> look_at <N/2, 0, N/2> right x*4/3 up y angle 57.82 }
light_source { <N/2, N, -N/2> rgb 1 }
#for (I, 0, N - 1)
  #for (J, 0, N - 1)
    sphere { <I, 0, J>, 0.4 texture { pigment { rgb <0.8, 0.5, 0.3> } finish { ambient 0.1 diffuse 0.8 phong 0.4 phong_size 40 } } }
  #end
#end
