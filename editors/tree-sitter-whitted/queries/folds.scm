; Folding: every block (objects, materials, functions, loops, settings...), multi-line
; arrays and argument lists, and block comments.
[
  (block)
  (array)
  (arguments)
  (block_comment)
] @fold
