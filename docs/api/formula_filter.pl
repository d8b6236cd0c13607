#!/usr/bin/perl
# Doxygen INPUT_FILTER of kelp's API reference: shows each formula as its LaTeX source.
#
# Doxygen renders \f$ ... \f$ and \f[ ... \f] with LaTeX (a TeX installation, slow) or MathJax (a
# CDN, or a copy of MathJax beside the pages). The reference must open from file:// with no
# network and build in seconds, so the formulas are shown as their source instead: an inline
# formula in <tt>, with the characters Doxygen would read as commands or tags escaped, a displayed
# one in a verbatim block (read literally). Line numbers are kept (the warnings' lines are the
# header's). Perl, not Python: Doxygen starts the filter once per header, and perl starts in a few
# milliseconds.
use strict;
use warnings;

sub esc {
  my ($t) = @_;
  $t =~ s/&/&amp;/g;
  $t =~ s/</&lt;/g;
  $t =~ s/>/&gt;/g;
  $t =~ s/([\\@])/\\$1/g;
  return $t;
}

local $/;
open(my $in, '<:raw', $ARGV[0]) or die "formula_filter: $ARGV[0]: $!\n";
my $text = <$in>;
$text =~ s/\\f\[(.*?)\\f\]/\\verbatim$1\\endverbatim/gs;
$text =~ s/\\f\$(.*?)\\f\$/'<tt>' . esc($1) . '<\/tt>'/gse;
binmode(STDOUT, ':raw');
print $text;
