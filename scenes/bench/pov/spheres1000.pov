// POV-Ray 3.7 equivalent of scenes/bench/spheres1000.scene: a 10x10x10 lattice of reflective
// spheres over a plane, one light, shadows, depth 5.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 5 adc_bailout 0.001 ambient_light rgb 1 }
background { rgb <0.05, 0.05, 0.1> }
camera { perspective location <14, 12, -16> look_at <4.5, 3.5, 4.5> right x*4/3 up y angle 57.82 }
light_source { <20, 30, -10> rgb 1 }
plane { y, -0.5 texture { pigment { rgb 0.6 } finish { ambient 0.1 diffuse 0.8 } } }
#for (I, 0, 9)
  #for (J, 0, 9)
    #for (K, 0, 9)
      sphere { <I, J, K>, 0.35
        texture { pigment { rgb <0.2 + I/12, 0.2 + J/12, 0.2 + K/12> }
                  finish { ambient 0.1 diffuse 0.7 phong 0.5 phong_size 60 reflection 0.3 } } }
    #end
  #end
#end
