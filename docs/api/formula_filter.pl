#!/usr/bin/perl
# Doxygen INPUT_FILTER of kelp's API reference: shows each formula as its LaTeX source.
#
# Doxygen renders \f$ ... \f$ and \f[ ... \f] with LaTeX (a TeX installation, slow) or MathJax (a
# CDN, or a copy of MathJax beside the pages). The reference must open from file:// with no
# network and build in seconds, so the formulas are shown as their source instead: an inline
# formula in <tt>, a displayed one in <pre>, with the characters Doxygen would read as commands or
# tags escaped. (Not \verbatim: Doxygen copies a verbatim block's lines whole, their /// too.)
# Line numbers are kept (the warnings' lines are the header's). Perl, not Python: Doxygen starts the filter once per header, and perl starts in a few
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

# A displayed formula's continuation line that starts with a sign and a space ("/// - g(eta)")
# would be read by Markdown as a list item, inside the <pre> too: its sign goes into a <span>.
sub display {
  my ($t) = @_;
  $t =~ s{(\n[ \t]*///[ \t]*)([-+*])(?=[ \t])}{$1<span>$2</span>}g;
  return $t;
}

local $/;
open(my $in, '<:raw', $ARGV[0]) or die "formula_filter: $ARGV[0]: $!\n";
my $text = <$in>;
$text =~ s/\\f\[(.*?)\\f\]/'<pre>' . display(esc($1)) . '<\/pre>'/gse;
$text =~ s/\\f\$(.*?)\\f\$/'<tt>' . esc($1) . '<\/tt>'/gse;
binmode(STDOUT, ':raw');
print $text;
