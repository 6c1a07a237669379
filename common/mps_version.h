/* What built this program: the git revision of the tree at build time
 * (`git describe --always --dirty --tags`, refreshed at every build by
 * cmake/git_rev.cmake), written into every snapshot and summary. */
#ifndef MPS_VERSION_H
#define MPS_VERSION_H

extern const char mps_git_rev[];

#endif
