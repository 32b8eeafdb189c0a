# The terminal every figure uses, so that PNG and SVG look alike across the project:
#   call 'terminal.gp' WIDTH HEIGHT [FONT_SIZE]
# with the variables fmt ('png' or 'svg') and out (the file) defined by the caller.
if (!exists("fmt")) fmt = 'png'
font_size = ARGC >= 3 ? ARG3 : '11'
if (fmt eq 'svg') { \
  set terminal svg size @ARG1,@ARG2 dynamic enhanced font 'DejaVu Sans,'.font_size background '#ffffff' \
} else { \
  set terminal pngcairo size @ARG1,@ARG2 enhanced font 'DejaVu Sans,'.font_size \
}
set output out
