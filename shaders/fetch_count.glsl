#ifndef DERMIS_FETCH_COUNT_GLSL
#define DERMIS_FETCH_COUNT_GLSL
// The fetch-counting build (compiled with -DDERMIS_COUNT_FETCHES): every texture
// fetch of a shader is written COUNTED(SITE(set, binding, kind), fetch), and every
// shader starts with COUNT_INVOCATION(). The counting build adds one to
// fetchCounts[site] per fetch and fetchCounts[0] per invocation, so a test can
// hold each pass's declared work (crate::work) against what its shader does.
// The normal build compiles both to nothing. Kinds follow crate::work::Filter.
#define FK_POINT 0u
#define FK_BILINEAR 1u
#define FK_COMPARE 2u
#define FK_TRILINEAR 3u
#define SITE(set, binding, kind) (1u + (uint(set) * 16u + uint(binding)) * 4u + (kind))
#ifdef DERMIS_COUNT_FETCHES
layout(std430, set = 3, binding = 0) buffer FetchCounts { uint fetchCounts[]; };
#define COUNTED(site, e) (atomicAdd(fetchCounts[site], 1u), (e))
#define COUNT_INVOCATION() atomicAdd(fetchCounts[0], 1u)
#else
#define COUNTED(site, e) (e)
#define COUNT_INVOCATION()
#endif
#endif
