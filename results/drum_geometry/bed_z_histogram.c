// Throw-away check used for results/drum_geometry/README.md: z range and z histogram (1/15 of the
// depth per bin) of the granules in the last frame of a drum run's result.h5.
//   cc -O2 -o bed_z_histogram bed_z_histogram.c $(pkg-config --cflags --libs hdf5)   (or -lhdf5_serial)
//   ./bed_z_histogram results/runs/drum_geometry/slice15/result.h5 0.015
#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
int main(int c, char **v){ hid_t f=H5Fopen(v[1],H5F_ACC_RDONLY,H5P_DEFAULT); hid_t p=H5Dopen2(f,"/frames/000000/position",H5P_DEFAULT), r=H5Dopen2(f,"/frames/000000/radius",H5P_DEFAULT);
 hsize_t n; hid_t s=H5Dget_space(r); H5Sget_simple_extent_dims(s,&n,NULL); double *P=malloc(n*24),*R=malloc(n*8);
 H5Dread(p,H5T_NATIVE_DOUBLE,H5S_ALL,H5S_ALL,H5P_DEFAULT,P); H5Dread(r,H5T_NATIVE_DOUBLE,H5S_ALL,H5S_ALL,H5P_DEFAULT,R);
 double mn=1,mx=-1; int hist[16]={0}, touch=0; double depth=atof(v[2]);
 for(hsize_t i=0;i<n;i++){double z=P[3*i+2]; if(z-R[i]<mn)mn=z-R[i]; if(z+R[i]>mx)mx=z+R[i]; int b=(int)(z/depth*15); if(b>=0&&b<15)hist[b]++; if(z-R[i]<0||z+R[i]>depth)touch++;}
 printf("%s n=%llu min(z-r)=%.5f max(z+r)=%.5f touching plates=%d\nz histogram (1 mm bins):",v[1],(unsigned long long)n,mn,mx,touch); for(int b=0;b<15;b++)printf(" %d",hist[b]); printf("\n"); return 0;}
