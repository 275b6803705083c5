import sys, subprocess, collections
data = sys.argv[1]
out = subprocess.run(["perf","script","-i",data,"-F","tid,time,ip,sym"],capture_output=True,text=True).stdout
samples=[]
for blk in out.split("\n\n"):
    lines=[l for l in blk.strip().split("\n") if l.strip()]
    if not lines: continue
    h=lines[0].split()
    tid=int(h[0]); t=float(h[1].rstrip(':'))
    sym=None; first=None
    for l in lines[1:]:
        p=l.split(None,1)
        if len(p)<2: continue
        addr,s=p
        if first is None: first=s
        if not addr.startswith('ffffffff') and s!='[unknown]' and not s.startswith('__memmove') and not s.startswith('__GI') and not s.startswith('_int_') and not s.startswith('__memset') :
            sym=s; break
    samples.append((t,tid,sym or ('k:'+str(first))))
samples.sort()
t0=samples[0][0]
tids=collections.Counter(s[1] for s in samples)
main=min(tids)
print("samples per tid", dict(tids))
# timeline of main thread: merge runs
runs=[]
for t,tid,s in samples:
    if tid!=main: continue
    if runs and runs[-1][1]==s: runs[-1][2]+=1; runs[-1][3]=t
    else: runs.append([t,s,1,t])
# coalesce: print runs >= N samples, aggregate small ones
N=int(sys.argv[2]) if len(sys.argv)>2 else 10
acc=collections.Counter(); start=None
for r in runs:
    if r[2]>=N:
        if acc: print("   small: %s" % ", ".join("%s:%d"%(k,v) for k,v in acc.most_common(6))); acc.clear()
        print("%7.3f %-45s %5d" % (r[0]-t0, r[1][:45], r[2]))
    else: acc[r[1]]+=r[2]
if acc: print("   small: %s" % ", ".join("%s:%d"%(k,v) for k,v in acc.most_common(6)))
other=collections.Counter(s for t,tid,s in samples if tid!=main)
print("worker:", ", ".join("%s:%d"%(k,v) for k,v in other.most_common(12)))
