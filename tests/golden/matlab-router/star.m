% camtool matlab-router: the Angel-11 Matlab GUI arrays (thesis display format)
% xy, lxy in 0.1 mm; velxy in encoder counts per 5 ms, major axis 480
% 1 job(s); each job homes, goes to its first point and lowers the tool

% job 1 of 1: stroke 1, contour 1, n = 10, first point x = 151, y = 86
xy = 
[   151   400   630   575   815   501   400   294     6   220   153; 
     86   265    86   431   639   642   999   645   665   428    86 ] 

lxy = 
[   249   230    55   240   314   101   106   288   214    67; 
    179   179   345   208     3   357   354    20   237   342 ] 

velxy = 
[   480   480   -77   480  -480  -136  -144  -480   433   -94; 
    345  -374   480   416     5   480  -480    33  -480  -480 ] 
