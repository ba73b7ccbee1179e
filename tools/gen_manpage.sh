#!/usr/bin/env bash
# Writes the sph(1) man page to stdout from the binary's own usage texts
# (`sph help` and `sph help COMMAND`), so the page and --help agree.
set -eu
sph=$1
version=$("$sph" --version | awk '{print $2}')
esc() { sed -e 's/\\/\\e/g' -e 's/^\./\\\&./' -e "s/^'/\\\\\&'/"; }
cat <<HEAD
.TH SPH 1 "" "sph $version" "User Commands"
.SH NAME
sph \\- large-strain elastic solid dynamics with SPH
.SH SYNOPSIS
.B sph
.I command
[\\fIoptions\\fR]
.SH DESCRIPTION
A YAML scene says what to simulate; \\fBsph run\\fR streams the particle
states to VTK files (a \\fI.pvd\\fR series ParaView opens), CSV tables,
\\fIsummary.json\\fR and, with an \\fBoutput.png\\fR block, PNG frames.
.PP
.nf
HEAD
"$sph" help | esc
echo ".fi"
echo ".SH COMMANDS"
for c in run check study list imgdiff bench render; do
  echo ".SS $c"
  echo ".nf"
  "$sph" help "$c" | esc
  echo ".fi"
done
cat <<'TAIL'
.SH EXIT STATUS
0 done (a stable run, matching images); 1 an unstable run or different
images; 2 bad input or usage; 3 an I/O or system failure; 128 + the
signal for a run stopped by SIGINT, SIGTERM or SIGHUP.
.SH FILES
The shipped scenes, \fIscenes/*.yaml\fR; the reference pages in
\fIdocs/\fR of the source tree.
TAIL
